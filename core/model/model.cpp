#include "core/model/model.hpp"

#include <algorithm>
#include <map>
#include <utility>

#include "core/model/element_kinds.hpp"
#include "core/model/hyper_dual.hpp"

namespace beamrail {
namespace {

// Registers the four couplings of an element between bodies a and b.
template <class S>
std::array<int, 4> couple(const std::vector<BodyT<S>>& bodies,
                          std::map<std::pair<int, int>, int>& index,
                          std::vector<BlockPattern::Block>& blocks, int a, int b) {
  const int fa = bodies[a].free_index, fb = bodies[b].free_index;
  auto block = [&](int r, int c) {
    if (r < 0 || c < 0) return -1;
    auto [it, inserted] = index.try_emplace({r, c}, static_cast<int>(blocks.size()));
    if (inserted) blocks.push_back({r, c});
    return it->second;
  };
  return {block(fa, fa), block(fa, fb), block(fb, fa), block(fb, fb)};
}

}  // namespace

template <class S>
void ModelT<S>::finalize() {
  free_bodies.clear();
  driven_bodies.clear();
  for (int i = 0; i < static_cast<int>(bodies.size()); ++i) {
    BodyT<S>& b = bodies[i];
    if (b.driven) driven_bodies.push_back(i);
    b.free_index = b.fixed ? -1 : static_cast<int>(free_bodies.size());
    if (!b.fixed) free_bodies.push_back(i);
  }
  n_states = kStatesPerBody * n_free();
  n_dofs = kDofsPerBody * n_free();

  pattern = BlockPattern{};
  std::map<std::pair<int, int>, int> index;
  for (int k = 0; k < n_free(); ++k) {
    index[{k, k}] = k;
    pattern.blocks.push_back({k, k});
  }
  for_each_element(*this, [&](auto kind, const auto& e, int) {
    using Kind = decltype(kind);
    pattern.element_blocks.push_back(
        couple(bodies, index, pattern.blocks, Kind::body1(e), Kind::body2(e)));
  });
  pattern.transposed.resize(pattern.blocks.size());
  for (size_t b = 0; b < pattern.blocks.size(); ++b)
    pattern.transposed[b] = index.at({pattern.blocks[b].col, pattern.blocks[b].row});
}

template void ModelT<double>::finalize();
template void ModelT<HyperDual>::finalize();

double characteristic_length(const Model& model) {
  double l = 0.0;
  for_each_element(
      model, [&l](auto kind, const auto& e, int) { l = std::max(l, decltype(kind)::length(e)); });
  return l > 0.0 ? l : 1.0;
}

std::vector<int> free_bodies_not_held(const Model& model) {
  std::vector<int> parent(model.bodies.size());
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  const auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for_each_element(model, [&](auto kind, const auto& e, int) {
    using Kind = decltype(kind);
    if (Kind::holds_all_six(e)) parent[root(Kind::body1(e))] = root(Kind::body2(e));
  });
  std::vector<char> grounded(model.bodies.size(), 0);
  for (size_t i = 0; i < model.bodies.size(); ++i)
    if (model.bodies[i].fixed) grounded[root(static_cast<int>(i))] = 1;
  std::vector<int> out;
  for (int i = 0; i < model.n_free(); ++i)
    if (!grounded[root(model.free_bodies[i])]) out.push_back(i);
  return out;
}

bool held_by_beams(const Model& model) { return free_bodies_not_held(model).empty(); }

}  // namespace beamrail
