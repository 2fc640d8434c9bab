#include "core/scene/auto_segments.hpp"

#include <Spectra/MatOp/SparseSymShiftSolve.h>
#include <Spectra/SymEigsShiftSolver.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

namespace beamrail {

std::vector<double> cantilever_bending_frequencies(const UniformBeam& beam, int plane, long n,
                                                   long count) {
  const double l = beam.length / static_cast<double>(n);
  const double ei = beam.ei[plane], m = beam.rho_area * l;
  const double j = beam.rho_i[plane] * l + m * l * l / 12.0;
  // Degrees of freedom (w, theta) of nodes 1..n; node 0 is clamped. K phi = lambda M phi with M
  // diagonal becomes the symmetric A = M^-1/2 K M^-1/2 (banded: nodes couple to neighbours only).
  const Eigen::Index dofs = 2 * n;
  Eigen::VectorXd d(dofs);
  for (long i = 1; i <= n; ++i) {
    const double share = i == n ? 0.5 : 1.0;
    d(2 * (i - 1)) = 1.0 / std::sqrt(share * m);
    d(2 * (i - 1) + 1) = 1.0 / std::sqrt(share * j);
  }
  Eigen::Matrix4d ke;
  ke << 12, 6 * l, -12, 6 * l,              //
      6 * l, 4 * l * l, -6 * l, 2 * l * l,  //
      -12, -6 * l, 12, -6 * l,              //
      6 * l, 2 * l * l, -6 * l, 4 * l * l;
  ke *= ei / (l * l * l);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(16 * n);
  for (long e = 0; e < n; ++e) {
    // Element e joins nodes e and e + 1; node i's dofs start at 2 (i - 1).
    const Eigen::Index first = 2 * (e - 1);
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c)
        if (first + r >= 0 && first + c >= 0)
          entries.emplace_back(first + r, first + c, d(first + r) * ke(r, c) * d(first + c));
  }
  Eigen::SparseMatrix<double> a(dofs, dofs);
  a.setFromTriplets(entries.begin(), entries.end());
  const auto hz = [](double lambda) {
    return std::sqrt(std::max(lambda, 0.0)) / (2.0 * std::numbers::pi);
  };
  std::vector<double> f;
  if (count > 0 && count < dofs / 4 && dofs > 64) {
    // The lowest few only: shift-invert Lanczos about 0 (A is positive definite), O(n) per step.
    Spectra::SparseSymShiftSolve<double> op(a);
    Spectra::SymEigsShiftSolver<Spectra::SparseSymShiftSolve<double>> eigs(
        op, count, std::min<Eigen::Index>(dofs, std::max<Eigen::Index>(2 * count + 1, 20)), 0.0);
    eigs.init();
    eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-13);
    if (eigs.info() == Spectra::CompInfo::Successful) {
      for (Eigen::Index i = 0; i < eigs.eigenvalues().size(); ++i)
        f.push_back(hz(eigs.eigenvalues()(i)));
      std::sort(f.begin(), f.end());
      return f;
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Eigen::MatrixXd(a),
                                                           Eigen::EigenvaluesOnly);
  const Eigen::Index keep = count > 0 ? std::min<Eigen::Index>(count, dofs) : dofs;
  for (Eigen::Index i = 0; i < keep; ++i) f.push_back(hz(eig.eigenvalues()(i)));
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
  // Per (plane, count of segments): the lowest frequencies computed so far, and whether they are
  // all the chain has.
  struct Computed {
    std::vector<double> values;
    bool all = false;
  };
  std::map<std::pair<int, long>, Computed> cache;
  const auto frequencies = [&](int plane, long n, size_t wanted) -> const std::vector<double>& {
    Computed& c = cache[{plane, n}];
    if (c.values.size() < wanted && !c.all) {
      c.values = cantilever_bending_frequencies(beam, plane, n, static_cast<long>(wanted));
      c.all = c.values.size() < wanted || c.values.size() == static_cast<size_t>(2 * n);
    }
    return c.values;
  };
  SegmentChoice out;
  out.beam = name;
  for (const long n : kLadder) {
    double worst = 0.0;
    int checked = 0;
    for (int plane = 0; plane < 2; ++plane) {
      // Every frequency up to the band (the first always), from the finest chain's values, and
      // the next one.
      size_t wanted = 2;
      while (frequencies(plane, 4 * n, wanted).size() == wanted &&
             frequencies(plane, 4 * n, wanted).back() <= target.max_frequency_hz)
        wanted *= 2;
      const std::vector<double>& finer = frequencies(plane, 4 * n, wanted);
      size_t count = 1;
      while (count < finer.size() && finer[count] <= target.max_frequency_hz) ++count;
      const std::vector<double>& coarse = frequencies(plane, n, count + 1);
      const std::vector<double>& fine = frequencies(plane, 2 * n, count + 1);
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
    out.first_frequency_hz = std::min(frequencies(0, n, 1)[0], frequencies(1, n, 1)[0]);
    if (worst <= target.frequency_error) return out;
  }
  out.reached = false;
  return out;
}

}  // namespace beamrail
