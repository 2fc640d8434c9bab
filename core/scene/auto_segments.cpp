#include "core/scene/auto_segments.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

namespace beamrail {

std::vector<double> cantilever_bending_frequencies(const UniformBeam& beam, int plane, long n) {
  const double l = beam.length / static_cast<double>(n);
  const double ei = beam.ei[plane], m = beam.rho_area * l;
  const double j = beam.rho_i[plane] * l + m * l * l / 12.0;
  // Degrees of freedom (w, theta) of nodes 1..n; node 0 is clamped.
  const int dofs = static_cast<int>(2 * n);
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(dofs, dofs);
  Eigen::Matrix4d ke;
  ke << 12, 6 * l, -12, 6 * l,              //
      6 * l, 4 * l * l, -6 * l, 2 * l * l,  //
      -12, -6 * l, 12, -6 * l,              //
      6 * l, 2 * l * l, -6 * l, 4 * l * l;
  ke *= ei / (l * l * l);
  for (long e = 0; e < n; ++e) {
    // Element e joins nodes e and e + 1; node i's dofs start at 2 (i - 1).
    const int first = static_cast<int>(2 * (e - 1));
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c)
        if (first + r >= 0 && first + c >= 0) k(first + r, first + c) += ke(r, c);
  }
  Eigen::VectorXd mass(dofs);
  for (long i = 1; i <= n; ++i) {
    const double share = i == n ? 0.5 : 1.0;
    mass(2 * (i - 1)) = share * m;
    mass(2 * (i - 1) + 1) = share * j;
  }
  // K phi = lambda M phi with M diagonal: the symmetric M^-1/2 K M^-1/2.
  const Eigen::VectorXd d = mass.cwiseInverse().cwiseSqrt();
  const Eigen::MatrixXd a = d.asDiagonal() * k * d.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a, Eigen::EigenvaluesOnly);
  std::vector<double> f;
  f.reserve(dofs);
  for (int i = 0; i < dofs; ++i)
    f.push_back(std::sqrt(std::max(eig.eigenvalues()(i), 0.0)) / (2.0 * std::numbers::pi));
  return f;
}

namespace {

// The estimated relative error of frequency k of the chain in n segments, from the chains in n,
// 2n and 4n: |f(n) - f(2n)| / (1 - 2^-p) / f(2n), p the observed order clamped to [1, 2] (the
// chain converges at order 2; a smaller observed order makes the estimate larger, never smaller).
double estimated_error(const std::vector<double>& n, const std::vector<double>& n2,
                       const std::vector<double>& n4, size_t k) {
  if (k >= n.size()) return std::numeric_limits<double>::infinity();
  const double d1 = std::abs(n[k] - n2[k]), d2 = std::abs(n2[k] - n4[k]);
  const double p = d2 > 0.0 ? std::clamp(std::log2(d1 / d2), 1.0, 2.0) : 2.0;
  return d1 / (1.0 - std::pow(2.0, -p)) / n2[k];
}

}  // namespace

SegmentChoice choose_segments(const std::string& name, const UniformBeam& beam,
                              const SegmentationTarget& target) {
  static constexpr long kLadder[] = {1,  2,  3,  4,  5,  6,  8,  10, 12, 14,  16, 20,
                                     24, 28, 32, 40, 48, 56, 64, 80, 96, 112, 128};
  std::map<std::pair<int, long>, std::vector<double>> cache;
  const auto frequencies = [&](int plane, long n) -> const std::vector<double>& {
    auto it = cache.find({plane, n});
    if (it == cache.end())
      it = cache.emplace(std::make_pair(plane, n), cantilever_bending_frequencies(beam, plane, n))
               .first;
    return it->second;
  };
  SegmentChoice out;
  out.beam = name;
  for (const long n : kLadder) {
    double worst = 0.0;
    int checked = 0;
    for (int plane = 0; plane < 2; ++plane) {
      const std::vector<double>& coarse = frequencies(plane, n);
      const std::vector<double>& fine = frequencies(plane, 2 * n);
      const std::vector<double>& finer = frequencies(plane, 4 * n);
      // Every frequency up to the band (the first always), from the finest chain's values.
      size_t count = 1;
      while (count < finer.size() && finer[count] <= target.max_frequency_hz) ++count;
      checked = std::max(checked, static_cast<int>(count));
      for (size_t k = 0; k < count; ++k)
        worst = std::max(worst, estimated_error(coarse, fine, finer, k));
      // A frequency in the band above the last one checked has a wavenumber between theirs and
      // the next one's; its error, ~ (wavenumber x segment length)^2 ~ frequency, is at most the
      // next one's times max_frequency_hz over its frequency.
      if (target.max_frequency_hz > finer[0] && count < finer.size())
        worst = std::max(worst, estimated_error(coarse, fine, finer, count) *
                                    target.max_frequency_hz / finer[count]);
    }
    out.segments = n;
    out.estimated_error = worst;
    out.frequencies_checked = checked;
    out.first_frequency_hz = std::min(frequencies(0, n)[0], frequencies(1, n)[0]);
    if (worst <= target.frequency_error) return out;
  }
  out.reached = false;
  return out;
}

}  // namespace beamrail
