#include "optimizer/batch/sampling.hpp"

#include <cstdint>

namespace beamrail {
namespace {

// SplitMix64: a small generator with the same sequence everywhere (the standard library's
// distributions are not specified to agree across implementations).
class Generator {
 public:
  explicit Generator(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  size_t below(size_t n) { return static_cast<size_t>(next() % n); }

 private:
  uint64_t state_;
};

std::vector<double> values_of(const DesignVariable& v) {
  if (!v.values.empty()) return v.values;
  std::vector<double> out;
  for (int k = 0; k < v.count; ++k)
    out.push_back(k + 1 == v.count ? v.upper : v.lower + (v.upper - v.lower) * k / (v.count - 1.0));
  return out;
}

}  // namespace

std::vector<Design> grid_designs(const std::vector<DesignVariable>& variables) {
  std::vector<Design> out{{}};
  for (const DesignVariable& v : variables) {
    std::vector<Design> next;
    for (const Design& prefix : out)
      for (double x : values_of(v)) {
        Design d = prefix;
        d.push_back(x);
        next.push_back(std::move(d));
      }
    out = std::move(next);
  }
  return out;
}

std::vector<Design> latin_hypercube(const std::vector<DesignVariable>& variables, int n,
                                    unsigned long seed) {
  Generator g(seed);
  std::vector<Design> out(n, Design(variables.size()));
  std::vector<size_t> strata(n);
  for (size_t j = 0; j < variables.size(); ++j) {
    for (int i = 0; i < n; ++i) strata[i] = static_cast<size_t>(i);
    for (size_t i = strata.size(); i > 1; --i) std::swap(strata[i - 1], strata[g.below(i)]);
    const DesignVariable& v = variables[j];
    for (int i = 0; i < n; ++i)
      out[i][j] =
          v.lower + (v.upper - v.lower) * (static_cast<double>(strata[i]) + g.uniform()) / n;
  }
  return out;
}

std::vector<Design> sweep_designs(const DesignStudy& study) {
  switch (study.sweep.sampling) {
    case SweepPlan::Sampling::kList:
      return study.sweep.rows;
    case SweepPlan::Sampling::kLhs:
      return latin_hypercube(study.variables, study.sweep.samples, study.sweep.seed);
    default:
      return grid_designs(study.variables);
  }
}

}  // namespace beamrail
