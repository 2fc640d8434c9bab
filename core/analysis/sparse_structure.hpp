// The sparse structure of a topology: which entries of the state Jacobian can be non-zero (a CSC
// pattern) and KLU's symbolic analysis of it (block triangular form and fill-reducing ordering),
// and the fill-reducing ordering of the modal analysis's symmetric matrices. They depend only on
// which free bodies the elements couple, so every design of one topology shares them: a
// SparseStructureCache hands the same immutable structure and ordering to every run that asks.
#pragma once

#include <klu.h>

#include <Eigen/Core>
#include <Eigen/SparseCore>
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

// A fill-reducing ordering of a symmetric matrix, as the permutation P: a sparse Cholesky or LDL^T
// factors P A P^T.
using SymmetricOrdering = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>;

// The ordering Eigen's SimplicialLDLT and SimplicialLLT choose for a matrix whose lower triangle
// has a's pattern: AMD on the pattern of A + A^T. It reads the pattern only (explicit zeros count,
// values do not), so every matrix of one pattern has it.
SymmetricOrdering symmetric_ordering(const Eigen::SparseMatrix<double>& a);

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

// Structures and orderings by topology (the free-body count and the coupled body pairs), shared
// by every model of that topology. Thread-safe. Keeps the most recently used few topologies.
class SparseStructureCache {
 public:
  std::shared_ptr<const SparseStructure> get(const Model& model);

  // The symmetric_ordering of a matrix on the model's velocity-level pattern (6 x 6 entries per
  // coupled body pair, dim n_dofs: the modal analysis's stiffness K and K + mu M), made from `a`
  // at the topology's first request, shared afterwards. Only the ordering is made (no
  // SparseStructure: a modal analysis needs neither the Jacobian's pattern nor KLU's analysis).
  std::shared_ptr<const SymmetricOrdering> ordering(const Model& model,
                                                    const Eigen::SparseMatrix<double>& a);

  long analyses() const;         // structures made
  long reuses() const;           // structure requests answered from the cache
  long orderings() const;        // orderings made
  long ordering_reuses() const;  // ordering requests answered from the cache

 private:
  struct Entry {
    int n_states = 0;
    std::vector<BlockPattern::Block> blocks;
    std::shared_ptr<const SparseStructure> structure;   // null until asked for
    std::shared_ptr<const SymmetricOrdering> ordering;  // null until asked for
  };
  // The entry of the model's topology, made most recently used; nullptr when there is none.
  Entry* find(const Model& model);    // under mutex_
  Entry& insert(const Model& model);  // under mutex_: a new entry, evicting the oldest if full
  static constexpr size_t kCapacity = 8;
  mutable std::mutex mutex_;
  std::vector<Entry> entries_;  // most recently used last
  long analyses_ = 0, reuses_ = 0, orderings_ = 0, ordering_reuses_ = 0;
};

}  // namespace beamrail
