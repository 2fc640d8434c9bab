// Stability at the extremes (issue 6): designs no human would draw must still give a completed
// solve with finite results that agree with a closed form or a conservation law, or a clear
// reported failure. Every case prints what it measured.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/model/element_kinematics.hpp"
#include "core/model/rotation.hpp"
#include "tests/support/scene_builder.hpp"
#include "tests/support/static_equilibrium.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::TransientRun;

constexpr double kE = 2.1e11, kG = 8.1e10, kPi = std::numbers::pi;

using testing::Scene;
using testing::vec;

using testing::body_index;
using testing::Equilibrium;
using testing::equilibrium;

ModalResult modes_of(const Model& model, int wanted) {
  Data data(model);
  ModalOptions options;
  options.modes = wanted;
  return solve_modal(model, options, data);
}

std::vector<double> elastic_eigenvalues(const ModalResult& r) {
  std::vector<double> out;
  for (const Mode& m : r.modes)
    if (m.kind != Mode::Kind::kRigid) out.push_back(m.eigenvalue);
  return out;
}

// Relative error, printed; returns it for the caller's assertion.
double report(const char* what, double measured, double exact) {
  const double error = std::abs(measured / exact - 1.0);
  std::printf("  %-46s % .12e  exact % .12e  rel. error %.2e\n", what, measured, exact, error);
  return error;
}

// ---------------------------------------------------------------------------------------------
// Independent references for chains of beams along x joined by rigid bodies.

struct ChainBeam {
  double length, ea, gj, eiy, eiz;
};
struct ChainBody {
  double mass;
  Vec3 inertia;  // principal, body axes = global axes
  Vec3 offset;   // centre of mass relative to the joint node [m]
};

// Linear static deflection at every node of a cantilever chain (node 0 clamped) under a force
// P_y at the last node, by the unit-load method: v_k = sum_i P/EI_i int (x_tip - x)(x_k - x) dx.
std::vector<double> chain_lateral_deflection(const std::vector<ChainBeam>& beams, double p) {
  std::vector<double> x(1, 0.0);
  for (const ChainBeam& b : beams) x.push_back(x.back() + b.length);
  const double tip = x.back();
  std::vector<double> v;
  for (size_t k = 1; k < x.size(); ++k) {
    double sum = 0.0;
    for (size_t i = 1; i <= k; ++i) {
      const auto prim = [&](double s) {
        return tip * x[k] * s - (tip + x[k]) * s * s / 2 + s * s * s / 3;
      };
      sum += p / beams[i - 1].eiz * (prim(x[i]) - prim(x[i - 1]));
    }
    v.push_back(sum);
  }
  return v;
}

struct ChainModes {
  std::vector<double> values;  // w^2, ascending [1/s^2]
  Eigen::MatrixXd vectors;     // columns: (dx, dtheta) of each joint node, global axes
};

// Modes of a chain by the textbook 12 x 12 space-frame element (Przemieniecki), assembled by
// hand: an oracle independent of the engine's kernels. Solved in long double, the lower half of
// the spectrum from the inverse problem (K^-1 M), so that it stays accurate where the spectrum
// spans many decades.
ChainModes chain_modes(const std::vector<ChainBeam>& beams, const std::vector<ChainBody>& bodies) {
  using Real = long double;
  using Matrix = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;
  const int n = 6 * static_cast<int>(bodies.size());
  Matrix k = Matrix::Zero(n, n), m = Matrix::Zero(n, n);
  for (size_t e = 0; e < beams.size(); ++e) {
    const ChainBeam& b = beams[e];
    const Real l = b.length, l2 = l * l, l3 = l2 * l;
    Eigen::Matrix<Real, 12, 12> ke = Eigen::Matrix<Real, 12, 12>::Zero();
    const auto put = [&](std::initializer_list<int> dofs, const Matrix& block) {
      const std::vector<int> d(dofs);
      for (size_t r = 0; r < d.size(); ++r)
        for (size_t c = 0; c < d.size(); ++c) ke(d[r], d[c]) += block(r, c);
    };
    Matrix bar(2, 2), bz(4, 4), by(4, 4);
    bar << 1, -1, -1, 1;
    put({0, 6}, Real(b.ea) / l * bar);
    put({3, 9}, Real(b.gj) / l * bar);
    bz << 12 / l3, 6 / l2, -12 / l3, 6 / l2, 6 / l2, 4 / l, -6 / l2, 2 / l, -12 / l3, -6 / l2,
        12 / l3, -6 / l2, 6 / l2, 2 / l, -6 / l2, 4 / l;
    by << 12 / l3, -6 / l2, -12 / l3, -6 / l2, -6 / l2, 4 / l, 6 / l2, 2 / l, -12 / l3, 6 / l2,
        12 / l3, 6 / l2, -6 / l2, 2 / l, 6 / l2, 4 / l;
    put({1, 5, 7, 11}, Real(b.eiz) * bz);
    put({2, 4, 8, 10}, Real(b.eiy) * by);
    for (int r = 0; r < 12; ++r)
      for (int c = 0; c < 12; ++c) {
        const int gr = 6 * (static_cast<int>(e) - 1) + r, gc = 6 * (static_cast<int>(e) - 1) + c;
        if (gr >= 0 && gc >= 0) k(gr, gc) += ke(r, c);
      }
  }
  for (size_t i = 0; i < bodies.size(); ++i) {
    // Kinetic energy about the joint node: centre velocity v + w x e.
    const ChainBody& b = bodies[i];
    Matrix t = Matrix::Identity(6, 6), mc = Matrix::Zero(6, 6);
    t.block(0, 3, 3, 3) = -skew<double>(b.offset).cast<Real>();
    for (int d = 0; d < 3; ++d) {
      mc(d, d) = b.mass;
      mc(3 + d, 3 + d) = b.inertia(d);
    }
    m.block(6 * i, 6 * i, 6, 6) = t.transpose() * mc * t;
  }
  const Eigen::GeneralizedSelfAdjointEigenSolver<Matrix> direct(k, m);
  const Eigen::LLT<Matrix> lm(m);
  const Matrix lower = lm.matrixL();
  const Matrix flexibility = lower.transpose() * Eigen::LLT<Matrix>(k).solve(lower);
  const Eigen::SelfAdjointEigenSolver<Matrix> inverse(
      Matrix(0.5 * (flexibility + flexibility.transpose())));
  const Matrix inverse_vectors = lm.matrixU().solve(inverse.eigenvectors());
  ChainModes out;
  out.vectors.resize(n, n);
  const Real middle = std::sqrt(direct.eigenvalues()(0) * direct.eigenvalues()(n - 1));
  for (int i = 0; i < n; ++i) {
    const bool low = direct.eigenvalues()(i) < middle;
    out.values.push_back(
        static_cast<double>(low ? 1 / inverse.eigenvalues()(n - 1 - i) : direct.eigenvalues()(i)));
    out.vectors.col(i) =
        (low ? inverse_vectors.col(n - 1 - i) : direct.eigenvectors().col(i)).cast<double>();
  }
  return out;
}

// Compares every elastic eigenvalue with the reference; returns the worst relative error.
double compare_spectra(const ModalResult& r, const std::vector<double>& reference) {
  const std::vector<double> got = elastic_eigenvalues(r);
  EXPECT_EQ(got.size(), reference.size());
  double worst = 0.0;
  for (size_t i = 0; i < std::min(got.size(), reference.size()); ++i)
    worst = std::max(worst, std::abs(got[i] / reference[i] - 1.0));
  if (!got.empty())
    std::printf("  %zu eigenvalues from %.3e to %.3e 1/s^2 (range %.1e): worst rel. error %.2e\n",
                got.size(), got.front(), got.back(), got.back() / got.front(), worst);
  return worst;
}

// Roots of the 2-degree-of-freedom chain ground -k1- m1 -k2- m2, computed without cancellation.
std::pair<double, double> two_mass_chain(double k1, double k2, double m1, double m2) {
  const double a = m1 * m2, b = m1 * k2 + m2 * (k1 + k2), c = k1 * k2;
  const double big = (b + std::sqrt(b * b - 4 * a * c)) / (2 * a);
  return {c / (a * big), big};
}

// The engine's eigenvalue of the mode whose shape lies along the given dofs of every body (in
// M-weighted measure, more than 99 %), matched to `exact` among those.
double mode_along(const ModalResult& r, const Model& model, int dof, double exact) {
  double best = NAN;
  for (const Mode& m : r.modes) {
    if (m.kind == Mode::Kind::kRigid) continue;
    double along = 0.0, all = 0.0;
    for (int k = 0; k < model.n_free(); ++k) {
      const Body& b = model.bodies[model.free_bodies[k]];
      for (int d = 0; d < 6; ++d) {
        const double mass = d < 3 ? b.mass : b.inertia(d - 3, d - 3);
        const double x = m.shape(6 * k + d);
        all += mass * x * x;
        if (d == dof) along += mass * x * x;
      }
    }
    if (along > 0.99 * all &&
        (std::isnan(best) || std::abs(m.eigenvalue / exact - 1) < std::abs(best / exact - 1)))
      best = m.eigenvalue;
  }
  return best;
}

// A cantilever chain along x: ground -beam 1- "mid" -beam 2- "tip", each beam its own material.
Scene two_beam_chain(const std::vector<ChainBeam>& b, const ChainBody& mid, const ChainBody& tip,
                     double e_ratio) {
  Scene s;
  s.material("m1", kE, kG).material("m2", e_ratio * kE, e_ratio * kG);
  const double l1 = b[0].length, l2 = b[1].length;
  s.custom("s1", b[0].ea / kE, b[0].gj / kG, b[0].eiy / kE, b[0].eiz / kE);
  s.custom("s2", b[1].ea / (e_ratio * kE), b[1].gj / (e_ratio * kG), b[1].eiy / (e_ratio * kE),
           b[1].eiz / (e_ratio * kE));
  s.body("mid", mid.mass, mid.inertia, Vec3(l1, 0, 0));
  s.body("tip", tip.mass, tip.inertia, Vec3(l1 + l2, 0, 0));
  s.beam("b1", "ground", "mid", Vec3::Zero(), Vec3(l1, 0, 0), "m1", "s1");
  s.beam("b2", "mid", "tip", Vec3(l1, 0, 0), Vec3(l1 + l2, 0, 0), "m2", "s2");
  return s;
}

// Zero crossings (upward) of a sampled signal, by linear interpolation; returns the mean period.
double mean_period(const std::vector<double>& t, const std::vector<double>& x) {
  std::vector<double> up;
  for (size_t i = 1; i < x.size(); ++i)
    if (x[i - 1] < 0.0 && x[i] >= 0.0)
      up.push_back(t[i - 1] + (t[i] - t[i - 1]) * (-x[i - 1]) / (x[i] - x[i - 1]));
  if (up.size() < 2) return NAN;
  return (up.back() - up.front()) / static_cast<double>(up.size() - 1);
}

// ---------------------------------------------------------------------------------------------
// Stiffness ratios 1e-6 and 1e6 between neighbouring beams: two beams in series.

TEST(Extremes, StiffnessRatiosBetweenNeighbouringBeams) {
  // A 10 x 12 mm rectangle: bending in y (E Iz) is the softer plane.
  const double area = 1.2e-4, iz = 1e-9, iy = 1.44e-9, ix = 1.8e-9;
  for (double ratio : {1e-6, 1e6}) {
    std::printf("beam 2 / beam 1 stiffness ratio %.0e\n", ratio);
    const std::vector<ChainBeam> beams = {
        {0.5, kE * area, kG * ix, kE * iy, kE * iz},
        {0.5, ratio * kE * area, ratio * kG * ix, ratio * kE * iy, ratio * kE * iz}};
    const ChainBody body{1.0, Vec3(1e-4, 1e-4, 1e-4), Vec3::Zero()};
    const Scene chain = two_beam_chain(beams, body, body, ratio);

    // Static: series compliances (axial) and the unit-load deflections (bending), both nodes.
    const std::vector<double> unit = chain_lateral_deflection(beams, 1.0);
    const double p = 1e-6 / unit[1];  // tip deflection 1e-6 of the length: linear range
    Scene lateral = chain;
    lateral.force("tip", Vec3(0, p, 0));
    const Equilibrium e = equilibrium(lateral);
    ASSERT_TRUE(e.result.ok) << e.result.message;
    EXPECT_LT(report("lateral deflection of mid", e.u("mid")(1), p * unit[0]), 1e-9);
    EXPECT_LT(report("lateral deflection of tip", e.u("tip")(1), p * unit[1]), 1e-9);
    const double c1 = beams[0].length / beams[0].ea, c2 = beams[1].length / beams[1].ea;
    const double n = 1e-6 / (c1 + c2);
    Scene axial = chain;
    axial.force("tip", Vec3(n, 0, 0));
    const Equilibrium f = equilibrium(axial);
    ASSERT_TRUE(f.result.ok) << f.result.message;
    EXPECT_LT(report("axial: N (l1/EA1 + l2/EA2)", f.u("tip")(0), n * (c1 + c2)), 1e-9);

    // Modal: axial and torsional pairs against the closed form, the whole spectrum against a
    // hand-assembled reference.
    const Model model = chain.model();
    const ModalResult r = modes_of(model, 12);
    ASSERT_TRUE(r.ok) << r.message;
    const auto [ax1, ax2] = two_mass_chain(1 / c1, 1 / c2, 1.0, 1.0);
    const auto [to1, to2] = two_mass_chain(beams[0].gj / 0.5, beams[1].gj / 0.5, 1e-4, 1e-4);
    EXPECT_LT(report("axial w^2, mode 1", mode_along(r, model, 0, ax1), ax1), 1e-9);
    EXPECT_LT(report("axial w^2, mode 2", mode_along(r, model, 0, ax2), ax2), 1e-9);
    EXPECT_LT(report("torsional w^2, mode 1", mode_along(r, model, 3, to1), to1), 1e-9);
    EXPECT_LT(report("torsional w^2, mode 2", mode_along(r, model, 3, to2), to2), 1e-9);
    const ChainModes reference = chain_modes(beams, {body, body});
    EXPECT_LT(compare_spectra(r, reference.values), 1e-9);

    // Transient: start in the lowest mode (velocity along its shape); the motion must keep its
    // period 2 pi / w and its energy.
    Scene moving = chain;
    const Eigen::VectorXd shape = reference.vectors.col(0);
    // Amplitude 1e-4 of the length (largest entry of the shape): linear to ~1e-8.
    const double scale = 1e-3 * std::sqrt(reference.values[0]) / shape.cwiseAbs().maxCoeff();
    for (int k = 0; k < 2; ++k) {
      const Eigen::VectorXd v = scale * shape.segment<6>(6 * k);
      moving.j["bodies"][k]["velocity"] = vec(v(0), v(1), v(2));
      moving.j["bodies"][k]["angular_velocity"] = vec(v(3), v(4), v(5));
    }
    const double period = 2 * kPi / std::sqrt(reference.values[0]);
    // Undamped stiff modes sit on the imaginary axis, where BDF of order 3-5 is unstable for
    // moderate w h: measured, the default order limit 5 needed 8.4 million steps for ratio 1e-6
    // (60 s) while order 2 (A-stable) needs 4.6 thousand. atol is what limits the accuracy here
    // (rtol 1e-12 gives the same); a tighter one is barred by the rounding of the stiff member's
    // forces (E A eps = 5.6e-3 N for ratio 1e6: atol 1e-11 ran past 20 s).
    TransientOptions to = testing::options(10 * period, period / 200, 1e-10, 1e-10);
    to.integrator.max_order = 2;
    to.max_seconds = 20;
    const TransientRun run = testing::simulate(moving.model(), to);
    ASSERT_TRUE(run.result.ok) << run.result.message;
    std::vector<double> t, x;
    double e0 = run.samples.front().sample.energy(), drift = 0.0;
    const int tip = body_index(model, "tip");
    for (const auto& s : run.samples) {
      t.push_back(s.sample.t);
      x.push_back(s.c[tip](1) - model.bodies[tip].position(1));
      drift = std::max(drift, std::abs(s.sample.energy() / e0 - 1));
    }
    EXPECT_LT(report("transient period of mode 1 [s]", mean_period(t, x), period), 1e-4);
    std::printf("  energy drift over 10 periods %.2e (BDF order <= 2: %ld steps)\n", drift,
                run.result.stats.steps);
    EXPECT_LT(drift, 1e-4);
  }
}

// ---------------------------------------------------------------------------------------------
// Beam lengths from 1e-6 m to 1e3 m in one scene: four cantilevers side by side (l/d = 20, tip
// mass 10 rho S l), each loaded to a tip deflection of 1e-6 of its length.

struct Circle {
  double area, i, ix;
  explicit Circle(double d)
      : area(kPi * d * d / 4), i(kPi * d * d * d * d / 64), ix(kPi * d * d * d * d / 32) {}
};

TEST(Extremes, BeamLengthsFromMicrometresToKilometresInOneScene) {
  const std::vector<double> lengths = {1e-6, 1e-3, 1.0, 1e3};
  Scene s;
  s.material("steel", kE, kG);
  std::vector<double> loads, masses;
  for (size_t k = 0; k < lengths.size(); ++k) {
    const double l = lengths[k], y = -3.0 * l * static_cast<double>(k);
    const Circle c(l / 20);
    const std::string n = std::to_string(k);
    s.custom("s" + n, c.area, c.ix, c.i, c.i);
    masses.push_back(10 * 7850 * c.area * l);
    const double j = masses.back() * l * l / 100;
    s.body("tip" + n, masses.back(), Vec3(j, j, j), Vec3(l, y, 0));
    s.beam("arm" + n, "ground", "tip" + n, Vec3(0, y, 0), Vec3(l, y, 0), "steel", "s" + n);
    loads.push_back(3 * kE * c.i * 1e-6 / (l * l));
  }
  Scene loaded = s;
  for (size_t k = 0; k < lengths.size(); ++k)
    loaded.force("tip" + std::to_string(k), Vec3(0, loads[k], 0));
  const Equilibrium e = equilibrium(loaded);
  ASSERT_TRUE(e.result.ok) << e.result.message;
  std::printf("  static: %d Newton iterations, %d load steps\n", e.result.iterations,
              e.result.load_steps);
  for (size_t k = 0; k < lengths.size(); ++k) {
    const std::string n = std::to_string(k);
    const double l = lengths[k], exact = loads[k] * l * l * l / (3 * kE * Circle(l / 20).i);
    char what[64];
    std::snprintf(what, sizeof what, "l = %.0e m: tip deflection P l^3/(3EI)", l);
    EXPECT_LT(report(what, e.u("tip" + n)(1), exact), 1e-9);
  }

  // Modal: each cantilever's modes; the frequencies span nine decades.
  const Model model = s.model();
  const ModalResult r = modes_of(model, 24);
  for (const std::string& w : r.warnings) std::printf("  warning: %s\n", w.c_str());
  ASSERT_TRUE(r.ok) << r.message;
  std::vector<double> reference;
  for (size_t k = 0; k < lengths.size(); ++k) {
    const double l = lengths[k];
    const Circle c(l / 20);
    const double j = masses[k] * l * l / 100;
    const ChainModes m = chain_modes({{l, kE * c.area, kG * c.ix, kE * c.i, kE * c.i}},
                                     {{masses[k], Vec3(j, j, j), Vec3::Zero()}});
    reference.insert(reference.end(), m.values.begin(), m.values.end());
  }
  std::sort(reference.begin(), reference.end());
  EXPECT_LT(compare_spectra(r, reference), 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Mass ratios 1e-6 and 1e6 between neighbouring bodies; a free pair of 1e-6 kg and 1e6 kg.

TEST(Extremes, MassRatiosBetweenNeighbouringBodies) {
  const double area = 1.2e-4, iz = 1e-9, iy = 1.44e-9, ix = 1.8e-9;
  const std::vector<ChainBeam> beams = {{0.5, kE * area, kG * ix, kE * iy, kE * iz},
                                        {0.5, kE * area, kG * ix, kE * iy, kE * iz}};
  for (double ratio : {1e-6, 1e6}) {
    std::printf("tip / mid mass ratio %.0e\n", ratio);
    const ChainBody mid{1.0, Vec3(1e-4, 1e-4, 1e-4), Vec3::Zero()};
    const ChainBody tip{ratio, ratio * mid.inertia, Vec3::Zero()};
    const Scene chain = two_beam_chain(beams, mid, tip, 1.0);
    const Model model = chain.model();
    const ModalResult r = modes_of(model, 12);
    for (const std::string& w : r.warnings) std::printf("  warning: %s\n", w.c_str());
    ASSERT_TRUE(r.ok) << r.message;
    const double k = beams[0].ea / 0.5;
    const auto [ax1, ax2] = two_mass_chain(k, k, 1.0, ratio);
    EXPECT_LT(report("axial w^2, mode 1", mode_along(r, model, 0, ax1), ax1), 1e-9);
    EXPECT_LT(report("axial w^2, mode 2", mode_along(r, model, 0, ax2), ax2), 1e-9);
    EXPECT_LT(compare_spectra(r, chain_modes(beams, {mid, tip}).values), 1e-9);
  }

  // A free pair, 1e-6 kg and 1e6 kg, joined by a 1 m steel wire of 1 mm: the light body
  // oscillates along the wire at w^2 = k (1/m + 1/M) while the pair drifts; momentum and energy
  // are conserved.
  const double m = 1e-6, big = 1e6, l = 1.0;
  const Circle c(1e-3);
  Scene pair;
  pair.material("steel", kE, kG).custom("wire", c.area, c.ix, c.i, c.i);
  pair.body("heavy", big, Vec3(1e5, 1e5, 1e5), Vec3::Zero());
  pair.body("light", m, Vec3(1e-10, 1e-10, 1e-10), Vec3(l, 0, 0));
  pair.beam("wire", "heavy", "light", Vec3::Zero(), Vec3(l, 0, 0), "steel", "wire");
  const double v0 = 1e-3;  // light body's velocity along the wire relative to the heavy one
  pair.j["bodies"][0]["velocity"] = vec(0.2, 0.1, 0);
  pair.j["bodies"][1]["velocity"] = vec(0.2 + v0, 0.1, 0);
  const Model model = pair.model();
  const double k = kE * c.area / l, w2 = k * (1 / m + 1 / big), period = 2 * kPi / std::sqrt(w2);
  TransientOptions o = testing::options(20 * period, period / 100, 1e-10, 1e-14);
  o.max_seconds = 20;
  const TransientRun run = testing::simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  // The centre of mass moves uniformly (momentum p0); its error is measured against the
  // distance it travelled.
  const Vec3 p0 = big * Vec3(0.2, 0.1, 0) + m * Vec3(0.2 + v0, 0.1, 0);
  double momentum = 0.0, drift = 0.0, recoil = 0.0;
  std::vector<double> t, x;
  const double e0 = run.samples.front().sample.energy();
  for (const auto& s : run.samples) {
    const double time = s.sample.t;
    const Vec3 centre = (big * s.c[1] + m * s.c[2]) / (big + m);
    const Vec3 expected = (m * Vec3(l, 0, 0) + p0 * time) / (big + m);
    if (time > 0)
      momentum = std::max(momentum, (centre - expected).norm() / (p0.norm() * time / (big + m)));
    drift = std::max(drift, std::abs(s.sample.energy() / e0 - 1));
    recoil = std::max(recoil, (s.pose[1].v - Vec3(0.2, 0.1, 0)).norm());
    t.push_back(time);
    x.push_back(s.c[2](0) - s.c[1](0) - l);
  }
  EXPECT_LT(report("free pair: period of the light body [s]", mean_period(t, x), period), 1e-6);
  std::printf(
      "  centre-of-mass error %.2e of its travel, heavy body's velocity change %.2e m/s (m v0 / M "
      "= %.0e), energy drift %.2e, %ld steps\n",
      momentum, recoil, m * v0 / big, drift, run.result.stats.steps);
  EXPECT_LT(momentum, 1e-12);
  EXPECT_LT(recoil, 1e-14);
  EXPECT_LT(drift, 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Slender (l/d = 1e4) and stubby (l/d = 0.5) cantilevers: statics and the tip-mass modes.

// Closed-form eigenvalues of a tip body (mass m, inertia j) on a cantilever: axial, torsional,
// and per bending plane the 2 x 2 problem [12 EI/l^3, -6 EI/l^2; -6 EI/l^2, 4 EI/l] x = w^2
// diag(m, J) x, solved without cancellation.
std::vector<double> tip_mass_eigenvalues(double l, double ea, double gj, double eiy, double eiz,
                                         double m, const Vec3& j) {
  std::vector<double> out = {ea / (l * m), gj / (l * j(0))};
  for (const auto& [ei, jj] : {std::pair{eiz, j(2)}, std::pair{eiy, j(1)}}) {
    const double k11 = 12 * ei / (l * l * l), k12 = -6 * ei / (l * l), k22 = 4 * ei / l;
    const double b = k11 / m + k22 / jj, c = (k11 * k22 - k12 * k12) / (m * jj);
    const double large = (b + std::sqrt(b * b - 4 * c)) / 2;
    out.push_back(c / large);
    out.push_back(large);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(Extremes, SlenderAndStubbyBeams) {
  struct Case {
    const char* name;
    double l, d, mass, inertia;
  };
  for (const Case& k : {Case{"slender, l/d = 1e4", 10.0, 1e-3, 0.1, 1e-6},
                        Case{"stubby, l/d = 0.5", 0.05, 0.1, 10.0, 0.1}}) {
    std::printf("%s\n", k.name);
    const Circle c(k.d);
    const double ei = kE * c.i, l = k.l;
    Scene s;
    s.material("steel", kE, kG).custom("s", c.area, c.ix, c.i, c.i);
    s.body("tip", k.mass, Vec3(k.inertia, k.inertia, k.inertia), Vec3(l, 0, 0));
    s.beam("arm", "ground", "tip", Vec3::Zero(), Vec3(l, 0, 0), "steel", "s");
    // Loads for a deflection (or rotation) of 1e-6 of the length (of a radian).
    const double p = 3 * ei * 1e-6 / (l * l), n = kE * c.area * 1e-6, t = kG * c.ix * 1e-6 / l;
    Scene bending = s, axial = s, torsion = s;
    bending.force("tip", Vec3(0, 0, -p));
    axial.force("tip", Vec3(n, 0, 0));
    torsion.torque("tip", Vec3(t, 0, 0));
    const Equilibrium eb = equilibrium(bending), ea = equilibrium(axial), et = equilibrium(torsion);
    ASSERT_TRUE(eb.result.ok && ea.result.ok && et.result.ok)
        << eb.result.message << ea.result.message << et.result.message;
    EXPECT_LT(report("bending: P l^3/(3EI)", -eb.u("tip")(2), p * l * l * l / (3 * ei)), 1e-9);
    EXPECT_LT(report("bending: P l^2/(2EI)", eb.r("tip")(1), p * l * l / (2 * ei)), 1e-9);
    EXPECT_LT(report("axial: P l/(ES)", ea.u("tip")(0), n * l / (kE * c.area)), 1e-9);
    EXPECT_LT(report("torsion: T l/(G Ix)", et.r("tip")(0), t * l / (kG * c.ix)), 1e-9);

    const ModalResult r = modes_of(s.model(), 6);
    ASSERT_TRUE(r.ok) << r.message;
    const Vec3 j(k.inertia, k.inertia, k.inertia);
    EXPECT_LT(
        compare_spectra(r, tip_mass_eigenvalues(l, kE * c.area, kG * c.ix, ei, ei, k.mass, j)),
        1e-9);
  }
}

// ---------------------------------------------------------------------------------------------
// A body spinning at 1e3 rad/s for 1e5 steps: torque-free, axisymmetric (Jx = Jy), so the spin
// rate wz stays, the transverse part of w turns at (Jz - Jx)/Jx wz in body axes, and the
// angular momentum (global) and the energy are kept.

TEST(Extremes, BodySpinningAtAThousandRadiansPerSecondForAHundredThousandSteps) {
  const double jx = 1e-3, jz = 2e-3, wz = 1e3, wt = 100;
  Scene s;
  s.body("top", 1.0, Vec3(jx, jx, jz), Vec3::Zero());
  s.last_body()["angular_velocity"] = vec(wt, 0, wz);
  const Model model = s.model();
  TransientOptions o = testing::options(1.0, 1e-3, 1e-10, 1e-10);
  o.integrator.max_step = 1e-5;  // 0.01 rad per step: 1e5 steps over 159 turns
  o.max_seconds = 30;
  const TransientRun run = testing::simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  const Mat3 j = model.bodies[1].inertia;
  const auto& first = run.samples.front();
  const Vec3 h0 = first.pose[1].A * (j * first.w[1]);
  const double e0 = 0.5 * first.w[1].dot(j * first.w[1]), precession = (jz - jx) / jx * wz;
  double norm = 0, momentum = 0, energy = 0, spin = 0, body_rate = 0;
  for (const auto& x : run.samples) {
    const Vec3& w = x.w[1];
    norm = std::max(norm, std::abs(x.q[1].norm() - 1));
    momentum = std::max(momentum, (x.pose[1].A * (j * w) - h0).norm() / h0.norm());
    energy = std::max(energy, std::abs(0.5 * w.dot(j * w) / e0 - 1));
    spin = std::max(spin, std::abs(w(2) / wz - 1));
    const Vec3 exact(wt * std::cos(precession * x.sample.t), wt * std::sin(precession * x.sample.t),
                     wz);
    body_rate = std::max(body_rate, (w - exact).norm() / wt);
  }
  std::printf(
      "  %ld steps (%.2f s): max ||q| - 1| %.2e, angular momentum %.2e, energy %.2e, spin rate "
      "%.2e, w vs closed form %.2e (of the transverse rate, after %.0f rad of precession)\n",
      run.result.stats.steps, run.result.stats.wall_seconds, norm, momentum, energy, spin,
      body_rate, precession * 1.0);
  EXPECT_GE(run.result.stats.steps, 100000);
  EXPECT_LT(norm, 1e-12);
  EXPECT_LT(momentum, 1e-9);
  EXPECT_LT(energy, 1e-9);
  EXPECT_LT(spin, 1e-9);
  EXPECT_LT(body_rate, 1e-6);
}

// ---------------------------------------------------------------------------------------------
// Near-singular inertia: a thin rod (Jx/Jy = 1e-8) on a short beam, and tumbling free.

TEST(Extremes, ThinRodBodyWithNearSingularInertia) {
  const double m = 1.0, length = 1.0, jy = m * length * length / 12, jx = 1e-8 * jy, l = 0.1;
  const Circle c(5e-3);
  Scene s;
  s.material("steel", kE, kG).custom("rod", c.area, c.ix, c.i, c.i);
  s.body("rod", m, Vec3(jx, jy, jy), Vec3(l + length / 2, 0, 0));
  s.beam("neck", "ground", "rod", Vec3::Zero(), Vec3(l, 0, 0), "steel", "rod");
  const Model model = s.model();
  const ModalResult r = modes_of(model, 6);
  ASSERT_TRUE(r.ok) << r.message;
  const ChainModes reference = chain_modes({{l, kE * c.area, kG * c.ix, kE * c.i, kE * c.i}},
                                           {{m, Vec3(jx, jy, jy), Vec3(length / 2, 0, 0)}});
  EXPECT_LT(compare_spectra(r, reference.values), 1e-9);
  const double torsion = kG * c.ix / (l * jx);
  EXPECT_LT(report("torsional w^2 = G Ix / (l Jx)", mode_along(r, model, 3, torsion), torsion),
            1e-9);

  // Swinging in its lowest mode (bending, a plane chosen by the shape): period and energy.
  Scene moving = s;
  const Eigen::VectorXd shape = reference.vectors.col(0);
  const Vec3 offset(length / 2, 0, 0);
  const double scale = 1e-4 * std::sqrt(reference.values[0]) / shape.cwiseAbs().maxCoeff();
  const Vec3 v = scale * (shape.head<3>() - offset.cross(Vec3(shape.tail<3>())));
  const Vec3 w = scale * shape.tail<3>();
  moving.last_body()["velocity"] = vec(v(0), v(1), v(2));
  moving.last_body()["angular_velocity"] = vec(w(0), w(1), w(2));
  const double period = 2 * kPi / std::sqrt(reference.values[0]);
  TransientOptions o = testing::options(10 * period, period / 200, 1e-10, 1e-12);
  o.max_seconds = 20;
  const TransientRun run = testing::simulate(moving.model(), o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  const int axis = std::abs(v(1)) > std::abs(v(2)) ? 1 : 2;
  std::vector<double> t, x;
  double drift = 0;
  const double e0 = run.samples.front().sample.energy();
  for (const auto& q : run.samples) {
    t.push_back(q.sample.t);
    x.push_back(q.c[1](axis));
    drift = std::max(drift, std::abs(q.sample.energy() / e0 - 1));
  }
  EXPECT_LT(report("period of the lowest mode [s]", mean_period(t, x), period), 1e-5);
  std::printf("  energy drift %.2e over 10 periods, %ld steps\n", drift, run.result.stats.steps);
  EXPECT_LT(drift, 1e-5);

  // Tumbling free end over end at 10 rad/s with a small spin about the rod's own axis.
  Scene free;
  free.body("rod", m, Vec3(jx, jy, jy), Vec3::Zero());
  free.last_body()["angular_velocity"] = vec(1e-3, 10, 0);
  const Model fm = free.model();
  TransientOptions fo = testing::options(10.0, 0.01, 1e-10, 1e-12);
  fo.max_seconds = 20;
  const TransientRun tumble = testing::simulate(fm, fo);
  ASSERT_TRUE(tumble.result.ok) << tumble.result.message;
  const Mat3 j = fm.bodies[1].inertia;
  const auto& a = tumble.samples.front();
  const Vec3 h0 = a.pose[1].A * (j * a.w[1]);
  double momentum = 0, energy = 0, axial = 0;
  for (const auto& q : tumble.samples) {
    momentum = std::max(momentum, (q.pose[1].A * (j * q.w[1]) - h0).norm() / h0.norm());
    energy = std::max(energy, std::abs(q.w[1].dot(j * q.w[1]) / a.w[1].dot(j * a.w[1]) - 1));
    axial = std::max(axial, std::abs(q.w[1](0) - 1e-3) / a.w[1].norm());
  }
  std::printf(
      "  free tumbling, 10 s: angular momentum %.2e, energy %.2e, spin about the axis kept to "
      "%.2e of |w|, %ld steps\n",
      momentum, energy, axial, tumble.result.stats.steps);
  EXPECT_LT(momentum, 1e-8);
  EXPECT_LT(energy, 1e-8);
  EXPECT_LT(axial, 1e-8);
}

}  // namespace
}  // namespace beamrail
