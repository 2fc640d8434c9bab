#include "core/analysis/sparse_structure.hpp"

#include <Eigen/OrderingMethods>
#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace beamrail {
namespace {

constexpr int kS = kStatesPerBody;

// Whether entry (r, s) of a 13 x 13 block can be non-zero.
bool structural(bool diagonal, int r, int s) {
  if (r >= 7) return true;  // accelerations depend on every coupled state
  if (!diagonal) return false;
  // dc/dt = v; the (zero) diagonal is stored too, so that SUNDIALS forms I - gamma J in place
  // (without it, SUNMatScaleAddI_Sparse rebuilds the matrix at every setup: 92 % of the run time
  // of a 1,000-body chain).
  if (r < 3) return s == r + 7 || s == r;
  return (s >= 3 && s <= 6) || s >= 10;  // dq/dt = q (x) (0, w) / 2
}

bool same_topology(int n_states, const std::vector<BlockPattern::Block>& blocks,
                   const Model& model) {
  if (n_states != model.n_states || blocks.size() != model.pattern.blocks.size()) return false;
  for (size_t b = 0; b < blocks.size(); ++b)
    if (blocks[b].row != model.pattern.blocks[b].row ||
        blocks[b].col != model.pattern.blocks[b].col)
      return false;
  return true;
}

// CSC structure of a matrix of size x size blocks on the model's block pattern, keeping the
// entries (r, s) of each block for which structural(diagonal, r, s) holds.
template <class Structural>
JacobianPattern block_pattern(const Model& model, int size, Structural&& structural) {
  const long n = static_cast<long>(size) * model.n_free();
  const auto& blocks = model.pattern.blocks;
  // Blocks by column body.
  std::vector<std::vector<int>> by_column(model.n_free());
  for (size_t b = 0; b < blocks.size(); ++b)
    by_column[blocks[b].col].push_back(static_cast<int>(b));
  for (auto& list : by_column)
    std::sort(list.begin(), list.end(),
              [&](int a, int b) { return blocks[a].row < blocks[b].row; });
  JacobianPattern p;
  p.positions.assign(blocks.size() * size * size, -1);
  p.column_starts.assign(n + 1, 0);
  for (long j = 0; j < n; ++j) {
    const int body = static_cast<int>(j / size), s = static_cast<int>(j % size);
    for (int b : by_column[body]) {
      const bool diagonal = blocks[b].row == blocks[b].col;
      for (int r = 0; r < size; ++r) {
        if (!structural(diagonal, r, s)) continue;
        p.positions[static_cast<size_t>(b) * size * size + size * r + s] =
            static_cast<long>(p.rows.size());
        p.rows.push_back(static_cast<long>(size) * blocks[b].row + r);
      }
    }
    p.column_starts[j + 1] = static_cast<long>(p.rows.size());
  }
  return p;
}

}  // namespace

SymmetricOrdering symmetric_ordering(const Eigen::SparseMatrix<double>& a) {
  // What SimplicialCholeskyBase::ordering does for UpLo = Lower and AMDOrdering: AMD on the full
  // symmetric matrix the lower triangle stands for gives P^-1.
  Eigen::SparseMatrix<double> full;
  full = a.selfadjointView<Eigen::Lower>();
  SymmetricOrdering inverse;
  Eigen::AMDOrdering<int>()(full, inverse);
  return inverse.inverse();
}

JacobianPattern make_jacobian_pattern(const Model& model) {
  return block_pattern(model, kS, structural);
}

SparseStructure::SparseStructure(const Model& model) : blocks_(model.pattern.blocks) {
  const auto start = std::chrono::steady_clock::now();
  pattern_ = make_jacobian_pattern(model);
  reduced_ = block_pattern(model, kVelocityStates, [](bool, int, int) { return true; });
  klu_l_common common;
  klu_l_defaults(&common);
  common.ordering = 1;  // COLAMD: the blocks of the Newton matrix are unsymmetric
  symbolic_ =
      klu_l_analyze(n_reduced(), reduced_.column_starts.data(), reduced_.rows.data(), &common);
  if (!symbolic_)
    throw std::runtime_error("KLU could not analyse the Jacobian pattern (status " +
                             std::to_string(common.status) + ")");
  analysis_seconds_ =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

SparseStructure::~SparseStructure() {
  if (symbolic_) {
    klu_l_common common;
    klu_l_defaults(&common);
    klu_l_free_symbolic(&symbolic_, &common);
  }
}

SparseStructureCache::Entry* SparseStructureCache::find(const Model& model) {
  for (size_t k = entries_.size(); k-- > 0;)
    if (same_topology(entries_[k].n_states, entries_[k].blocks, model)) {
      std::rotate(entries_.begin() + static_cast<long>(k),
                  entries_.begin() + static_cast<long>(k) + 1, entries_.end());
      return &entries_.back();
    }
  return nullptr;
}

SparseStructureCache::Entry& SparseStructureCache::insert(const Model& model) {
  if (entries_.size() == kCapacity) entries_.erase(entries_.begin());
  entries_.push_back({model.n_states, model.pattern.blocks, nullptr, nullptr});
  return entries_.back();
}

std::shared_ptr<const SparseStructure> SparseStructureCache::get(const Model& model) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (const Entry* e = find(model); e && e->structure) {
      ++reuses_;
      return e->structure;
    }
  }
  // Analysed outside the lock, so other topologies are served meanwhile; two threads meeting a
  // new topology at once both analyse it and the first one stored is kept.
  auto structure = std::make_shared<const SparseStructure>(model);
  std::lock_guard<std::mutex> lock(mutex_);
  ++analyses_;
  Entry* e = find(model);
  if (!e) e = &insert(model);
  if (!e->structure) e->structure = std::move(structure);
  return e->structure;
}

std::shared_ptr<const SymmetricOrdering> SparseStructureCache::ordering(
    const Model& model, const Eigen::SparseMatrix<double>& a) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (const Entry* e = find(model); e && e->ordering) {
      ++ordering_reuses_;
      return e->ordering;
    }
  }
  auto made = std::make_shared<const SymmetricOrdering>(symmetric_ordering(a));
  std::lock_guard<std::mutex> lock(mutex_);
  ++orderings_;
  Entry* e = find(model);
  if (!e) e = &insert(model);
  if (!e->ordering) e->ordering = std::move(made);
  return e->ordering;
}

long SparseStructureCache::analyses() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return analyses_;
}

long SparseStructureCache::reuses() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return reuses_;
}

long SparseStructureCache::orderings() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return orderings_;
}

long SparseStructureCache::ordering_reuses() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return ordering_reuses_;
}

}  // namespace beamrail
