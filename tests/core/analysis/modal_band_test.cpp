// The band chosen for rtol (core/analysis/modal_band.hpp): its rules on uncoupled modes, where
// every response is a closed form, and its estimate against the error band-limited runs make
// against full-model runs of a cantilever.
#include "core/analysis/modal_band.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/analysis/modal_integrator.hpp"
#include "tests/support/heavy_tip_cantilever.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::motion_error;
using testing::options;
using testing::scene_from_json;
using testing::simulate;
using testing::TransientRun;

// Two free bodies (12 degrees of freedom), M = I, K = diag(lambda): mode k is unit vector e_k.
// The modes in ascending order: dof d of body b is row 6 b + d.
struct Uncoupled {
  Eigen::VectorXd lambda;
  Eigen::MatrixXd phi;
  Eigen::SparseMatrix<double> m0, k0;
  double mu = 1e-3;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> shifted;
  std::vector<int> rows;  // row of each mode

  explicit Uncoupled(const std::vector<std::pair<int, double>>& modes) {
    const int n = 12;
    lambda.resize(static_cast<Eigen::Index>(modes.size()));
    phi = Eigen::MatrixXd::Zero(n, lambda.size());
    k0.resize(n, n);
    m0.resize(n, n);
    m0.setIdentity();
    std::vector<Eigen::Triplet<double>> k;
    for (size_t i = 0; i < modes.size(); ++i) {
      lambda(static_cast<Eigen::Index>(i)) = modes[i].second;
      phi(modes[i].first, static_cast<Eigen::Index>(i)) = 1.0;
      k.emplace_back(modes[i].first, modes[i].first, modes[i].second);
      rows.push_back(modes[i].first);
    }
    k0.setFromTriplets(k.begin(), k.end());
    shifted.compute(Eigen::SparseMatrix<double>(k0 + mu * m0));
  }
};

TEST(ModalBand, UncoupledModesFollowTheirClosedForms) {
  // Translations x, y of body 0 (rows 0, 1) and x of body 1 (row 6), a rotation (row 3), and the
  // rest; w^2 ascending; modes 2 and 3 (rows 6 and 7) share a frequency.
  const Uncoupled u({{0, 1.0},
                     {1, 4.0},
                     {6, 100.0},
                     {7, 100.0},
                     {3, 400.0},
                     {2, 1e4},
                     {4, 2e4},
                     {5, 3e4},
                     {8, 4e4},
                     {9, 5e4},
                     {10, 6e4},
                     {11, 7e4}});
  // A jump of a unit force on every degree of freedom: mode k's static response is
  // 1 / (w_k^2 + mu) on its own row; the motion's size is that of mode 0 (row 0).
  BandExcitation jump{BandExcitation::Kind::kForce, Eigen::VectorXd::Ones(12), 0.0, 1.0};
  const double motion = 1.0 / (1.0 + u.mu);
  const auto dropped_after = [&](int m) {  // largest translation left out, the closed form
    double largest = 0.0;
    for (int k = m; k < 12; ++k)
      if (u.rows[k] % 6 < 3) largest = std::max(largest, 1.0 / (u.lambda(k) + u.mu));
    return largest / motion;
  };
  for (double tolerance : {0.5, 0.2, 5e-3, 1e-4, 1e-5}) {
    const BandChoice c =
        choose_band(u.lambda, u.phi, u.m0, u.shifted, u.mu, {jump}, {0, 1}, tolerance);
    ASSERT_TRUE(c.met) << tolerance;
    EXPECT_NEAR(c.estimate, dropped_after(static_cast<int>(c.modes)), 1e-12) << tolerance;
    EXPECT_LE(c.estimate, tolerance);
    // The smallest number: one mode fewer (at a cluster's boundary) misses the tolerance.
    int fewer = static_cast<int>(c.modes) - 1;
    if (fewer == 3) fewer = 2;  // modes 2 and 3 are one cluster
    if (fewer >= 1) {
      EXPECT_GT(dropped_after(fewer), tolerance) << tolerance;
    }
    EXPECT_NE(c.modes, 3) << "a cluster split";
  }
  // 0.2: mode 1 (w^2 4, 0.25 of the motion) must be kept; then mode 2's cluster (row 6, 0.01)
  // goes in whole or not at all: 2 modes leave 0.01 <= 0.2.
  EXPECT_EQ(choose_band(u.lambda, u.phi, u.m0, u.shifted, u.mu, {jump}, {0, 1}, 0.2).modes, 2);
  // The rotation (row 3, mode 4: 2.5e-3 of the motion) does not count while something
  // translates: 4 modes leave translations of 1e-4 only.
  EXPECT_EQ(choose_band(u.lambda, u.phi, u.m0, u.shifted, u.mu, {jump}, {0, 1}, 1e-3).modes, 4);

  // A velocity rings at v / w: unit velocity on row 1 (mode 1, w = 2) and row 2 (w = 100);
  // the motion's size is v / w_1 (w_1 = 1, the lowest).
  BandExcitation kick{BandExcitation::Kind::kVelocity, Eigen::VectorXd::Zero(12), 0.0, 1.0};
  kick.vector(1) = 1.0;
  kick.vector(2) = 1.0;
  BandChoice v = choose_band(u.lambda, u.phi, u.m0, u.shifted, u.mu, {kick}, {0, 1}, 0.6);
  EXPECT_EQ(v.modes, 1);
  EXPECT_NEAR(v.estimate, 0.5, 1e-12);  // row 1: 1 / 2
  v = choose_band(u.lambda, u.phi, u.m0, u.shifted, u.mu, {kick}, {0, 1}, 0.3);
  EXPECT_EQ(v.modes, 2);
  EXPECT_NEAR(v.estimate, 0.01, 1e-12);  // row 2: 1 / 100
  v = choose_band(u.lambda, u.phi, u.m0, u.shifted, u.mu, {kick}, {0, 1}, 1e-3);
  EXPECT_EQ(v.modes, 6);  // through row 2's mode (index 5): nothing left
  EXPECT_NEAR(v.estimate, 0.0, 1e-15);

  // A load changing at a rate r rings a mode at r / w of its static response: a ramp on row 1
  // (mode 1, w = 2) at r = 0.2 rad/s: 0.1 of 1 / (4 + mu).
  BandExcitation ramp{BandExcitation::Kind::kForce, Eigen::VectorXd::Zero(12), 0.2, 1.0};
  ramp.vector(1) = 1.0;
  const BandChoice r = choose_band(u.lambda, u.phi, u.m0, u.shifted, u.mu, {ramp}, {0, 1}, 1.0);
  EXPECT_EQ(r.modes, 1);
  EXPECT_NEAR(r.estimate, 0.1, 1e-12);

  // Rigid modes stay: w^2 = 0 first, then the band may be as small as that one mode.
  const Uncoupled rigid({{0, 0.0},
                         {1, 4.0},
                         {2, 9.0},
                         {3, 16.0},
                         {4, 25.0},
                         {5, 36.0},
                         {6, 49.0},
                         {7, 64.0},
                         {8, 81.0},
                         {9, 100.0},
                         {10, 121.0},
                         {11, 144.0}});
  BandExcitation far{BandExcitation::Kind::kForce, Eigen::VectorXd::Zero(12), 0.0, 1.0};
  far.vector(7) = 1.0;  // on mode 7 only (row 7: a translation of body 1)
  const BandChoice keep =
      choose_band(rigid.lambda, rigid.phi, rigid.m0, rigid.shifted, rigid.mu, {far}, {1}, 0.5);
  EXPECT_EQ(keep.modes, 8);  // through mode 7, whatever the tolerance
  // Nothing that rings: only the rigid mode.
  EXPECT_EQ(
      choose_band(rigid.lambda, rigid.phi, rigid.m0, rigid.shifted, rigid.mu, {}, {1}, 1e-9).modes,
      1);
}

// The cantilever of the speed targets in 40 segments (1 m, 10 mm square steel), its tip stepped
// by 1 N in -y at the start and 0.5 N in +z at 12.3 ms.
std::string two_step_cantilever() {
  return R"({"materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq",
               "segments": 40}],
    "loads": [{"type": "force", "body": "tip", "value": [0, -1, 0],
               "time": {"type": "step", "at": 0.0}},
              {"type": "force", "body": "tip", "value": [0, 0, 0.5],
               "time": {"type": "step", "at": 0.0123}}]})";
}

TransientRun modal_run(const Model& model, double rtol, double band, bool choose) {
  TransientOptions o = options(0.03, 1e-4, rtol, 1e-2 * rtol);
  o.integrator.method = IntegratorMethod::kModal;
  o.integrator.max_frequency_hz = band;
  o.integrator.choose_band = choose;
  return simulate(model, o);
}

// The estimate against the error the band makes (an estimate: the ringing's peak over the
// samples and the nonlinear forcing are approximated): for each rtol, the band chosen,
// then a run with that band at rtol 1e-10 (the band's own error, the integration's removed) against
// the full model at 1e-10; and the chosen run's whole error against rtol. Returns the band's
// error over the estimate, per rtol.
std::vector<double> check_band_estimate(const std::string& label, const std::string& scene,
                                        const std::vector<double>& rtols) {
  const Model model = scene_from_json(scene);
  int tip = 0;
  while (model.bodies[tip].name != "tip") ++tip;
  std::vector<double> ratios;
  const TransientRun full = modal_run(model, 1e-10, 0.0, false);
  EXPECT_TRUE(full.result.ok) << label << ": " << full.result.message;
  if (!full.result.ok) return ratios;
  int previous_modes = 0;
  for (double rtol : rtols) {
    const TransientRun chosen = modal_run(model, rtol, 0.0, true);
    EXPECT_TRUE(chosen.result.ok) << label << ": " << chosen.result.message;
    if (!chosen.result.ok || chosen.result.phases.size() != 1u) {
      ADD_FAILURE() << label << ": " << chosen.result.phases.size() << " phases";
      return ratios;
    }
    const std::string& why = chosen.result.phases[0].reason;
    double band = 0.0, estimate = 0.0;
    int modes = 0, all = 0;
    if (std::sscanf(why.c_str(), "band %lf Hz chosen for rtol: %d of %d", &band, &modes, &all) !=
        3) {
      ADD_FAILURE() << label << ": " << why;
      return ratios;
    }
    const size_t at = why.find("estimated at ");
    EXPECT_NE(at, std::string::npos) << why;
    estimate = std::stod(why.substr(at + 13));
    const TransientRun banded = modal_run(model, 1e-10, band * (1.0 + 1e-9), false);
    EXPECT_TRUE(banded.result.ok) << banded.result.message;
    // The error relative to the largest motion (for a step twice the static response the
    // estimate is relative to).
    const double band_error = motion_error(banded, full, tip);
    const double run_error = motion_error(chosen, full, tip);
    std::printf(
        "%s, rtol %.0e: band %.4g Hz (%d of %d modes), estimate %.2e, the band's error "
        "%.2e (%.2f of the estimate), the run's %.2e (%.3f rtol), %ld steps\n",
        label.c_str(), rtol, band, modes, all, estimate, band_error, band_error / estimate,
        run_error, run_error / rtol, chosen.result.stats.steps);
    EXPECT_LE(estimate, rtol) << label;
    EXPECT_GT(modes, previous_modes) << label << ": a tighter rtol keeps more modes";
    EXPECT_LE(band_error, estimate) << label << ", rtol " << rtol;
    // The chosen run's error follows rtol (issue 17's proportionality: within [1e-3, 10] rtol).
    EXPECT_LE(run_error, 10.0 * rtol) << label << ", rtol " << rtol;
    EXPECT_GE(run_error, 1e-3 * rtol) << label << ", rtol " << rtol;
    ratios.push_back(band_error / estimate);
    previous_modes = modes;
  }
  return ratios;
}

TEST(ModalBand, EstimateBoundsTheErrorOfTheBandItChooses) {
  // Not far above the error either (measured: 0.42 .. 0.53).
  for (double ratio :
       check_band_estimate("two steps", two_step_cantilever(), {1e-3, 1e-4, 1e-5, 1e-6}))
    EXPECT_GE(ratio, 0.25);
}

// The same cantilever excited by what else the estimate rates: a load ramped up over 2 ms (two
// kinks: each rings at rate / w of the mode's static response), a table whose slope changes at
// four knots, and an initial velocity of the tip (ringing at 1 / w of it) with no load at all.
TEST(ModalBand, EstimateBoundsTheErrorOfRampsTablesAndInitialVelocities) {
  const std::string base = two_step_cantilever();
  const std::string head = base.substr(0, base.find(R"("loads")"));
  const std::string ramp = head + R"("loads": [{"type": "force", "body": "tip", "value": [0, -1, 0],
      "time": {"type": "ramp", "from": 0.001, "to": 0.003}}]})";
  const std::string table =
      head + R"("loads": [{"type": "force", "body": "tip", "value": [0, -1, 0.5],
      "time": {"type": "table", "t": [0, 0.002, 0.005, 0.011, 0.02], "v": [0, 1, 0.4, 0.9, 0.9]}}]})";
  std::string moving = head.substr(0, head.rfind(','));
  const std::string tip = R"({"name": "tip", "position": [1, 0, 0]})";
  moving.replace(moving.find(tip), tip.size(),
                 R"({"name": "tip", "position": [1, 0, 0], "velocity": [0, 0.01, -0.004]})");
  moving += "}";
  for (const auto& [label, scene] : {std::pair<std::string, std::string>{"ramp", ramp},
                                     {"table", table},
                                     {"initial velocity", moving}})
    check_band_estimate(label, scene, {1e-3, 1e-5});
}

// The heavy-tip cantilever (tests/support/heavy_tip_cantilever.hpp) under a tip load in -y
// ramped smoothly over 0.3 s and held, for 1 s. Bending pulls the tip in (the shortening, second
// order in the deflection); its axial mode (about 730 Hz) lies above the band chosen for rtol
// 1e-6, which the transverse load does not ring, so the estimate cannot see it. Quasi-static
// there, the tip's axial motion loses its inertia, which stiffens the bending: the motion's
// frequency is off by about half the ratio of that motion's kinetic energy to the band's, and
// the error grows with the deflection squared.
std::string ramped_heavy_tip(double load) {
  return testing::heavy_tip_cantilever(
      R"("value": [0, )" + std::to_string(-load) +
      R"(, 0], "time": {"type": "smooth_ramp", "from": 0, "to": 0.3})");
}

// Its warning's estimate of the error, or -1 when the run did not warn of it.
double inertia_warning_estimate(const TransientRun& run) {
  for (const std::string& w : run.result.warnings) {
    if (w.find("band-limited run") == std::string::npos ||
        w.find("kinetic energy") == std::string::npos)
      continue;
    const size_t at = w.find("estimated at ");
    if (at == std::string::npos) return -1.0;
    return std::stod(w.substr(at + 13));
  }
  return -1.0;
}

// The ramped heavy tip under `load`, by `method` with the band chosen for rtol, and its error
// against the full modal model at rtol 1e-10 (which bdf at rtol 1e-10 meets to 4e-10 of the
// motion).
struct BandedRun {
  TransientRun run;
  double error = 0.0;
};
BandedRun banded_heavy_tip(double load, IntegratorMethod method, double rtol) {
  const Model model = scene_from_json(ramped_heavy_tip(load));
  TransientOptions o = options(1.0, 5e-3, 1e-10, 1e-12);
  o.integrator.method = IntegratorMethod::kModal;
  const TransientRun full = simulate(model, o);
  EXPECT_TRUE(full.result.ok) << full.result.message;
  o = options(1.0, 5e-3, rtol, 1e-3 * rtol);
  o.integrator.method = method;
  o.integrator.choose_band = true;
  BandedRun banded{simulate(model, o)};
  EXPECT_TRUE(banded.run.result.ok) << banded.run.result.message;
  EXPECT_GT(banded.run.result.max_frequency_hz, 0.0) << "not band-limited (at first)";
  banded.error = motion_error(banded.run, full, testing::body_index(model, "tip"));
  return banded;
}

// Measured against the full modal model at rtol 1e-10 (which bdf at rtol 1e-10 meets to 4e-10 of
// the motion): at 1 N (slopes of 3e-3) a 37 Hz band left 17 rtol, estimated at 56 rtol; at 0.1 N
// 0.18 rtol and no warning (estimated at 0.6 rtol). Before the estimate, the run said ok and
// nothing else. (auto, which chose the band itself, widens it instead: the next test.)
TEST(ModalBand, ARunWarnsWhenTheModesItKeepsQuasiStaticCarryInertia) {
  const double rtol = 1e-6;
  for (double load : {0.1, 1.0}) {
    const auto [banded, error] = banded_heavy_tip(load, IntegratorMethod::kModal, rtol);
    const double estimate = inertia_warning_estimate(banded);
    std::printf("modal, %.1f N: band %.4g Hz, error %.2e (%.2f rtol), warning's estimate %.2e\n",
                load, banded.result.max_frequency_hz, error, error / rtol, estimate);
    if (load < 0.5) {
      EXPECT_LT(error, rtol);
      EXPECT_EQ(estimate, -1.0) << "a warning where the run meets rtol";
    } else {
      EXPECT_GT(error, 5.0 * rtol) << "the band's dropped inertia shows";
      ASSERT_GT(estimate, 0.0) << "no warning";
      EXPECT_GT(estimate, error);
      EXPECT_LT(estimate, 5.0 * error);
    }
  }
}

// auto, whose band was chosen for rtol, goes on with every mode from the step where the dropped
// inertia's estimate passes half of rtol: the 1 N case above meets rtol and does not warn, the
// 0.1 N case too, against the same reference. Before, auto left 17 rtol at 1 N and warned.
TEST(ModalBand, AutoIntegratesEveryModeOnceTheChosenBandsQuasiStaticModesCarryInertia) {
  const double rtol = 1e-6;
  for (double load : {0.1, 1.0}) {
    const auto [run, error] = banded_heavy_tip(load, IntegratorMethod::kAuto, rtol);
    const std::vector<MethodPhase>& phases = run.result.phases;
    std::printf("auto, %.1f N: band %.4g Hz, %zu phases, error %.2e (%.2f rtol)\n", load,
                run.result.max_frequency_hz, phases.size(), error, error / rtol);
    for (const MethodPhase& p : phases)
      std::printf("  t = %.4g s: %s (%s)\n", p.t, p.method.c_str(), p.reason.c_str());
    EXPECT_LT(error, rtol);
    EXPECT_EQ(inertia_warning_estimate(run), -1.0) << "a warning where the run meets rtol";
    if (load > 0.5) {
      ASSERT_EQ(phases.size(), 2u);
      EXPECT_EQ(phases[1].method, "modal");
      EXPECT_NE(phases[1].reason.find("every mode integrated from here"), std::string::npos)
          << phases[1].reason;
      EXPECT_GT(phases[1].t, 0.0);
      EXPECT_LT(phases[1].t, 0.5);
    }
  }
}

// Under a harmonic load the motion goes at the load's frequency, and the inertia the quasi-static
// modes leave out drifts its phase at that rate, not at the band's lowest: a 1.5 m cantilever of
// 20 x 10 mm steel in 30 segments with a 0.3 kg tip under 5 N at 60 Hz (f1 about 2.5 Hz), 0.1 s,
// rtol 1e-6, against every mode at rtol 1e-8 (5.9e-13 of the motion off Verner 8(7) at rtol
// 1e-11). auto with a band chosen for rtol (20 of 180 modes, 1,050 Hz) kept it to the end and came
// out 5.0 rtol off, silent (by 0.3 s: 8.8 rtol, widened at 0.106 s); it now widens at 0.023 s,
// 0.66 rtol. A given band of 1,050 Hz (modal) left 5.0 rtol and did not warn; now it warns of
// 1.2e-5 (by 0.3 s: 5.9e-5 left, 5.8e-6 warned before, 1.2e-4 now).
TEST(ModalBand, TheInertiaOfQuasiStaticModesUnderAHarmonicLoadDriftsAtItsFrequency) {
  const Model model = scene_from_json(R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.02, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 0.3, "inertia": [1e-6, 1e-6, 1e-6], "position": [1.5, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1.5, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq",
               "segments": 30}],
    "loads": [{"type": "force", "body": "tip", "value": [0, 0, -5],
               "time": {"type": "harmonic", "frequency": 60}}]})");
  const double rtol = 1e-6, t_end = 0.1;
  TransientOptions o = options(t_end, 1e-3, 1e-8, 1e-14);
  o.integrator.method = IntegratorMethod::kModal;
  const TransientRun full = simulate(model, o);
  ASSERT_TRUE(full.result.ok) << full.result.message;
  o = options(t_end, 1e-3, rtol, 1.2e-13);
  o.integrator.method = IntegratorMethod::kAuto;
  o.integrator.choose_band = true;
  const TransientRun run = simulate(model, o);
  ASSERT_TRUE(run.result.ok) << run.result.message;
  const double error = motion_error(run, full, testing::body_index(model, "tip"));
  const std::vector<MethodPhase>& phases = run.result.phases;
  std::printf("harmonic load, auto, band chosen: error %.2f rtol, %zu phases, the last at %.3g s\n",
              error / rtol, phases.size(), phases.back().t);
  EXPECT_LT(error, rtol);
  ASSERT_EQ(phases.size(), 2u);
  EXPECT_NE(phases[1].reason.find("every mode integrated from here"), std::string::npos)
      << phases[1].reason;
  EXPECT_LT(phases[1].t, 0.05);

  o.integrator.method = IntegratorMethod::kModal;
  o.integrator.choose_band = false;
  o.integrator.max_frequency_hz = 1050.0;
  const TransientRun given = simulate(model, o);
  ASSERT_TRUE(given.result.ok) << given.result.message;
  const double given_error = motion_error(given, full, testing::body_index(model, "tip"));
  const double estimate = inertia_warning_estimate(given);
  std::printf("harmonic load, modal, 1,050 Hz: error %.2e, the warning's estimate %.2e\n",
              given_error, estimate);
  EXPECT_GT(given_error, 3.0 * rtol);
  EXPECT_GT(estimate, given_error);
  EXPECT_LT(estimate, 5.0 * given_error);
}

// A cantilever vibrating across both of its bending planes (1 m of 10 mm steel, a 0.5 kg tip
// started at 0.5 and 0.2 m/s across it) in `segments` segments.
std::string biaxial_cantilever(int segments) {
  return R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"sq10": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 0.5, "inertia": [1e-4, 1e-4, 1e-4], "position": [1, 0, 0],
                "velocity": [0, 0.5, 0.2]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq10",
               "segments": )" +
         std::to_string(segments) + "}]}";
}

// The estimate of a given band's warning of the ringing it drops, or -1 when it did not warn.
double given_band_estimate(const TransientRun& run) {
  for (const std::string& w : run.result.warnings) {
    const size_t at = w.find("would ring with about ");
    if (at != std::string::npos) return std::stod(w.substr(at + 22));
  }
  return -1.0;
}

// A band given (max_frequency_hz) is estimated as a chosen one is, and the run warns when the
// ringing it drops is above rtol. The biaxial cantilever with a 30 Hz band leaves out the high
// modes of the tip's initial velocity: 6.0e-3 of the motion over 0.3 s against the full model,
// where the run's only warning (the quasi-static modes' inertia) said 5.7e-4. The estimate counts
// the modes that deform no element as rigid (by w^2 at most 1e-8 of the highest, from 28
// segments on it took the first bending modes and said 1.3).
TEST(ModalBand, AGivenBandWarnsOfTheRingingItDrops) {
  const double t_end = 0.3;
  const Model model = scene_from_json(biaxial_cantilever(16));
  const int tip = testing::body_index(model, "tip");
  TransientOptions o = options(t_end, 1e-2, 1e-7, 1e-11);
  o.integrator.method = IntegratorMethod::kModal;
  const TransientRun full = simulate(model, o);
  ASSERT_TRUE(full.result.ok) << full.result.message;
  o = options(t_end, 1e-2, 1e-6, 1e-10);
  o.integrator.method = IntegratorMethod::kModal;
  o.integrator.max_frequency_hz = 30.0;
  const TransientRun banded = simulate(model, o);
  ASSERT_TRUE(banded.result.ok) << banded.result.message;
  const double error = motion_error(banded, full, tip);
  const double estimate = given_band_estimate(banded);
  std::printf("16 segments, 30 Hz: error %.3e, the warning's estimate %.3e, the inertia's %.3e\n",
              error, estimate, inertia_warning_estimate(banded));
  ASSERT_GT(estimate, 0.0) << "no warning";
  EXPECT_GT(estimate, 0.5 * error);
  EXPECT_LT(estimate, 3.0 * error);
  EXPECT_LT(inertia_warning_estimate(banded), 0.2 * error) << "the other warning covers it now";

  // No warning where the ringing is within rtol.
  o.integrator.rtol = 1e-2;
  o.integrator.atol = 1e-6;
  EXPECT_EQ(given_band_estimate(simulate(model, o)), -1.0);

  // The same estimate in more segments (made as the run starts: the band's quasi-static
  // iteration fails on this beam in 32 segments at 0.03 s, docs/transient_measurements.md).
  o.integrator.rtol = 1e-6;
  o.integrator.atol = 1e-10;
  for (int segments : {28, 32}) {
    const double more =
        given_band_estimate(simulate(scene_from_json(biaxial_cantilever(segments)), o));
    std::printf("%d segments: the warning's estimate %.3e\n", segments, more);
    EXPECT_NEAR(more, estimate, 0.1 * estimate);
  }
}

}  // namespace
}  // namespace beamrail
