// The sparse structure of a topology: which entries of the state Jacobian can be non-zero (a CSC
// pattern) and KLU's symbolic analysis of it (block triangular form and fill-reducing ordering).
// Both depend only on which free bodies the elements couple, so every design of one topology
// shares them: a SparseStructureCache hands the same immutable structure to every run that asks.
#pragma once

#include <klu.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/model/model.hpp"

namespace beamrail {

// Structure of the sparse state Jacobian: per pattern block of 13 x 13, the entries that can be
// non-zero (dc/dt = v, dq/dt depends on q and w only, accelerations on everything coupled), in
// compressed sparse columns with sorted row indices. The diagonal is always stored, so that the
// integrators form I - gamma J in place.
struct JacobianPattern {
  std::vector<long> column_starts;  // n_states + 1
  std::vector<long> rows;           // nnz
  // Position in the value array of entry (r, s) of pattern block b: positions[b * 169 + 13 r + s],
  // -1 when the entry is structurally zero.
  std::vector<long> positions;
  long nnz() const { return static_cast<long>(rows.size()); }
};

JacobianPattern make_jacobian_pattern(const Model& model);

// Per free body, 7 position states (c, q) and 6 velocity states (v, w).
constexpr int kPositionStates = 7;
constexpr int kVelocityStates = 6;

// The pattern, the pattern of the velocity-level system the solver factors (the Schur complement
// of the position states, 6 x 6 per block: the position rows of a Newton matrix I - gamma J only
// couple a body to itself) and KLU's analysis of the latter. Immutable once made: KLU reads the
// symbolic analysis without modifying it, so runs on several threads share one.
class SparseStructure {
 public:
  // Throws std::runtime_error when KLU cannot analyse the pattern.
  explicit SparseStructure(const Model& model);
  ~SparseStructure();
  SparseStructure(const SparseStructure&) = delete;
  SparseStructure& operator=(const SparseStructure&) = delete;

  long n() const { return static_cast<long>(pattern_.column_starts.size()) - 1; }
  long n_reduced() const { return static_cast<long>(reduced_.column_starts.size()) - 1; }
  const JacobianPattern& pattern() const { return pattern_; }  // the Jacobian, 13 x 13 blocks
  const JacobianPattern& reduced() const { return reduced_; }  // velocity level, 6 x 6 blocks
  const std::vector<BlockPattern::Block>& blocks() const { return blocks_; }
  klu_l_symbolic* symbolic() const { return symbolic_; }         // of the reduced pattern
  double analysis_seconds() const { return analysis_seconds_; }  // pattern + KLU analysis

 private:
  std::vector<BlockPattern::Block> blocks_;  // diagonal blocks first (block k = free body k)
  JacobianPattern pattern_;
  JacobianPattern reduced_;
  klu_l_symbolic* symbolic_ = nullptr;
  double analysis_seconds_ = 0.0;
};

// Structures by topology (the free-body count and the coupled body pairs), shared by every model
// of that topology. Thread-safe. Keeps the most recently used few.
class SparseStructureCache {
 public:
  std::shared_ptr<const SparseStructure> get(const Model& model);

  long analyses() const;  // structures made
  long reuses() const;    // requests answered from the cache

 private:
  struct Entry {
    int n_states = 0;
    std::vector<BlockPattern::Block> blocks;
    std::shared_ptr<const SparseStructure> structure;
  };
  static constexpr size_t kCapacity = 8;
  mutable std::mutex mutex_;
  std::vector<Entry> entries_;  // most recently used last
  long analyses_ = 0, reuses_ = 0;
};

}  // namespace beamrail
