// Rails in static analysis: a carriage on one prismatic rail against the cantilever formula
// P a^3 / (3 E I) (docs/model.md "Validation"), the energy formulation's configurational force that
// leaves an unrestrained carriage without equilibrium, and a carriage on two parallel rails held by
// a drive rod, whose reactions in each rail match the hand solution of the statically indeterminate
// system.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "core/analysis/static_analysis.hpp"
#include "core/model/element_forces.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "core/model/rotation.hpp"
#include "tests/support/scenes.hpp"

namespace beamrail {
namespace {

constexpr double kE = 2.1e11, kG = 8.0769e10;

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

struct Solution {
  StaticResult result;
  Vec3 displacement = Vec3::Zero();
  Vec3 rotation = Vec3::Zero();  // rotation vector of the carriage (initial orientation identity)
};

Solution solve(const Model& model, Data& data) {
  StaticOptions options;
  options.tolerance = 1e-13;
  Solution s;
  s.result = solve_static(model, options, data);
  const int c = model.free_bodies[0];
  s.displacement = data.pose[c].u;
  s.rotation = rotation_vector(data.pose[c].A);
  return s;
}

// ---------------------------------------------------------------------------------------------
// (a) One carriage on one prismatic rail along x from ground, carriage at distance a.

// Rail section 12 mm along local y (= global y) by 20 mm along local z: bending in y uses
// Iz = h w^3 / 12, bending in z uses Iy = w h^3 / 12.
constexpr double kWidth = 0.012, kHeight = 0.02;

std::string single_rail(double a, const std::string& formulation, const Vec3& load) {
  const std::string x = num(a);
  return R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"bar": {"shape": "rectangle", "width": 0.012, "height": 0.02}},
    "bodies": [{"name": "carriage", "mass": 1.5, "inertia": [2e-3, 1e-3, 1e-3],
                "position": [)" +
         x + R"(, 0, 0]}],
    "rails": [{"name": "guide", "type": "prismatic", "body1": "ground", "body2": "carriage",
               "point1": [0, 0, 0], "point2": [)" +
         x + R"(, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "bar",
               "formulation": ")" +
         formulation + R"("}],
    "loads": [{"type": "force", "body": "carriage", "value": [)" +
         num(load(0)) + ", " + num(load(1)) + ", " + num(load(2)) + "]}]}";
}

double relative(double measured, double exact) { return std::abs(measured / exact - 1); }

TEST(RailStatic, LateralLoadOnACarriageDeflectsLikeACantileverAtAnyDistance) {
  const double p = 1e-2;
  const double iz = kHeight * std::pow(kWidth, 3) / 12, iy = kWidth * std::pow(kHeight, 3) / 12;
  for (const double a : {0.1, 0.2, 0.5, 1.0}) {
    for (const int axis : {1, 2}) {
      const Vec3 load = p * Vec3::Unit(axis);
      const Model model = testing::scene_from_json(single_rail(a, "paper", load));
      Data data(model);
      const Solution s = solve(model, data);
      ASSERT_TRUE(s.result.ok) << s.result.message;
      // Load +P in y: deflection +P a^3 / (3 E Iz), rotation about z +P a^2 / (2 E Iz).
      // Load +P in z: deflection +P a^3 / (3 E Iy), rotation about y -P a^2 / (2 E Iy).
      const double ei = kE * (axis == 1 ? iz : iy);
      const double deflection = p * a * a * a / (3 * ei);
      const double rotation = (axis == 1 ? 1 : -1) * p * a * a / (2 * ei);
      const double rot_measured = axis == 1 ? s.rotation(2) : s.rotation(1);
      const double e_defl = relative(s.displacement(axis), deflection);
      const double e_rot = relative(rot_measured, rotation);
      std::printf(
          "paper, a = %.1f m, load in %c: deflection %.12e m (P a^3/3EI %.12e, error %.1e), "
          "rotation error %.1e, slide dx %.1e m, %d iterations, singular directions %d\n",
          a, axis == 1 ? 'y' : 'z', s.displacement(axis), deflection, e_defl, e_rot,
          s.displacement(0), s.result.iterations, s.result.singular_directions);
      EXPECT_LT(e_defl, 1e-9);
      EXPECT_LT(e_rot, 1e-9);
      // Nothing pushes the carriage along the rail in the paper formulation.
      EXPECT_LT(std::abs(s.displacement(0)), 1e-12 * a);
      // The slide along the rail has no stiffness: solved minimum-norm, with a warning.
      EXPECT_EQ(s.result.singular_directions, 1);
      EXPECT_FALSE(s.result.warnings.empty());
    }
  }
}

// The energy formulation keeps dU/dl, a real configurational force along the rail: at fixed lateral
// load the total potential of the cantilever, -P^2 l^3 / (6 E I), falls as l grows, so a
// frictionless carriage slides outwards and has no equilibrium. The force along the rail is
// P^2 a^2 / (2 E I) = P theta (theta the tip rotation); with P = 1 N it is 8e-6 to 8e-4 N, far
// above the solver's rounding floor (with P = 0.01 N and a = 0.1 m it is 8.3e-10 N, below the floor
// of 2.6e-9 N, and the solver accepts the initial distance as an equilibrium within rounding).
// The static solve must not report a lateral equilibrium at the initial carriage distance: either
// it fails or the carriage moves along the rail by more than its lateral deflection.
struct RunawayCase {
  double a;
  Solution s;
};

std::vector<RunawayCase> runaway_cases() {
  std::vector<RunawayCase> out;
  for (const double a : {0.1, 0.2, 0.5, 1.0}) {
    const Model model = testing::scene_from_json(single_rail(a, "energy", Vec3::UnitY()));
    Data data(model);
    out.push_back({a, solve(model, data)});
  }
  return out;
}

TEST(RailStatic, EnergyFormulationHasNoEquilibriumForAnUnrestrainedLoadedCarriage) {
  const double p = 1.0, iz = kHeight * std::pow(kWidth, 3) / 12;
  for (const RunawayCase& c : runaway_cases()) {
    const Solution& s = c.s;
    std::printf(
        "energy, a = %.1f m, P = 1 N in y: ok = %d%s%s, %d iterations, %d load steps, residual "
        "%.3e N of load %.3e N; dx = %.3e m, dy = %.3e m (P a^3/3EI = %.3e m)\n",
        c.a, s.result.ok, s.result.message.empty() ? "" : ": ", s.result.message.c_str(),
        s.result.iterations, s.result.load_steps, s.result.residual_norm, s.result.reference_force,
        s.displacement(0), s.displacement(1), p * c.a * c.a * c.a / (3 * kE * iz));
    for (const std::string& w : s.result.warnings) std::printf("  warning: %s\n", w.c_str());
    EXPECT_TRUE(!s.result.ok || std::abs(s.displacement(0)) > std::abs(s.displacement(1)));
  }
}

// A reported equilibrium must balance the loads. (Found by this test: the solver once returned
// ok = true with its residual equal to the whole load, after the carriage ran off to ~1e22 m:
// far out, the lateral stiffness fell below the minimum-norm solver's rank threshold and the
// "converged to rounding" exit accepted the vanishing correction.) The runaway carriage has no
// equilibrium, and the solver must say so.
TEST(RailStatic, StaticSolveReportsOkOnlyWhenTheLoadsAreBalanced) {
  for (const RunawayCase& c : runaway_cases()) {
    std::printf("a = %.1f m: ok = %d, residual %.3e N of load %.3e N\n", c.a, c.s.result.ok,
                c.s.result.residual_norm, c.s.result.reference_force);
    if (c.s.result.ok) {
      EXPECT_LT(c.s.result.residual_norm, 1e-6 * c.s.result.reference_force);
    }
    EXPECT_FALSE(c.s.result.ok);
    EXPECT_NE(c.s.result.message.find("no equilibrium"), std::string::npos) << c.s.result.message;
    EXPECT_TRUE(c.s.result.no_equilibrium) << c.s.result.message;
  }
}

// ---------------------------------------------------------------------------------------------
// (b) A carriage on two parallel prismatic rails along x from ground at z = -s and z = +s, the
// carriage centre at (a, 0, 0), held along x by a drive rod (a beam along x from the origin to the
// carriage centre with Ix = Iy = Iz = 1e-16 m^4: axial load only, to ~1e-8 of the rails' bending
// stiffness), loaded by P in -y at the point (a, 0, e).

constexpr double kA = 0.4, kS = 0.1;  // as written in the scene below
constexpr double kRailWidth = 0.016, kRailHeight = 0.024, kRodI = 1e-16;

std::string two_rails(const std::string& formulation, double p, double e) {
  const std::string f = R"(, "formulation": ")" + formulation + "\"";
  return R"({
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10}},
    "sections": {"bar": {"shape": "rectangle", "width": 0.016, "height": 0.024},
                 "drive": {"shape": "custom", "S": 1e-4, "Ix": 1e-16, "Iy": 1e-16, "Iz": 1e-16}},
    "bodies": [{"name": "carriage", "mass": 5.0, "inertia": [0.03, 0.02, 0.02],
                "position": [0.4, 0, 0]}],
    "rails": [
      {"name": "left", "type": "prismatic", "body1": "ground", "body2": "carriage",
       "point1": [0, 0, -0.1], "point2": [0.4, 0, -0.1], "point3": [0, 1, -0.1],
       "material": "steel", "section": "bar")" +
         f + R"(},
      {"name": "right", "type": "prismatic", "body1": "ground", "body2": "carriage",
       "point1": [0, 0, 0.1], "point2": [0.4, 0, 0.1], "point3": [0, 1, 0.1],
       "material": "steel", "section": "bar")" +
         f + R"(}],
    "beams": [{"name": "drive_rod", "body1": "ground", "body2": "carriage", "point1": [0, 0, 0],
               "point2": [0.4, 0, 0], "point3": [0, 1, 0], "material": "steel",
               "section": "drive")" +
         f + R"(}],
    "loads": [{"type": "force", "body": "carriage", "point": [0.4, 0, )" +
         num(e) + R"(], "value": [0, )" + num(-p) + R"(, 0]}]})";
}

// A cantilever of length a from ground to the carriage, attached at z = z_i (on the carriage's
// centre line x = a, y = 0).
struct Member {
  double z, ei, gj;  // ei: bending in the x-y plane (E Iz, local y = global y)
};

struct MemberForces {
  double fy, mz, mx;  // acting ON the member at end 2 (the carriage end), global = local axes
};

struct HandSolution {
  double v, theta_z, psi;  // carriage centre drop (y), rotation about z, twist about x
  std::vector<MemberForces> forces;
};

// The hand solution. Unknowns: the carriage centre's y displacement v, its rotation theta_z about z
// and its twist psi about x (the load in -y excites no other motion, to first order). Member i
// attaches at R_i = (0, 0, z_i) from the centre, so its tip moves by v + (theta x R_i)_y =
// v - psi z_i =: v_i, turns by theta_z about z and twists by psi about x. Its end-2 forces (acting
// ON the member, docs/model.md K2 rows 2, 6, 4) are
//   F_i  = 12 EI / a^3 v_i - 6 EI / a^2 theta_z,
//   Mz_i = -6 EI / a^2 v_i + 4 EI / a   theta_z,
//   Mx_i = GJ / a psi.
// The carriage receives the opposite: force -F_i (in y) at R_i and moment (-Mx_i, 0, -Mz_i). With
// the load (0, -P, 0) at (0, 0, e) from the centre, its equilibrium is
//   forces in y:         -sum F_i - P = 0                    ->  sum F_i = -P,
//   moments about z:     -sum Mz_i + (R x F)_z = 0, (R x F)_z = 0 for R along z, F along y
//                                                            ->  sum Mz_i = 0,
//   moments about x:     (R_i x (0, -F_i, 0))_x = z_i F_i and ((0, 0, e) x (0, -P, 0))_x = e P, so
//                        sum (z_i F_i - Mx_i) + e P = 0      ->  sum (Mx_i - z_i F_i) = e P.
// Symmetric case e = 0 with equal rails at z = -+s: psi = 0 solves the x equation, the rails share
// the load equally (checked below).
HandSolution hand_solution(const std::vector<Member>& members, double a, double p, double e) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (const Member& k : members) {
    const double k12 = 12 * k.ei / (a * a * a), k6 = 6 * k.ei / (a * a), k4 = 4 * k.ei / a,
                 t = k.gj / a;
    // Coefficients of (v, theta_z, psi), v_i = v - z_i psi.
    const Eigen::RowVector3d f(k12, -k6, -k12 * k.z);  // F_i
    const Eigen::RowVector3d mz(-k6, k4, k6 * k.z);    // Mz_i
    const Eigen::RowVector3d mx(0, 0, t);              // Mx_i
    m.row(0) += f;
    m.row(1) += mz;
    m.row(2) += mx - k.z * f;
  }
  const Eigen::Vector3d x = m.fullPivLu().solve(Eigen::Vector3d(-p, 0, e * p));
  HandSolution h{x(0), x(1), x(2), {}};
  for (const Member& k : members) {
    const double vi = h.v - h.psi * k.z;
    h.forces.push_back({12 * k.ei / (a * a * a) * vi - 6 * k.ei / (a * a) * h.theta_z,
                        -6 * k.ei / (a * a) * vi + 4 * k.ei / a * h.theta_z, k.gj / a * h.psi});
  }
  return h;
}

// Relative difference with a stated scale (so that quantities that vanish can be compared too).
double scaled(double measured, double exact, double scale) {
  return std::abs(measured - exact) / scale;
}

TEST(RailStatic, CarriageOnTwoRailsSharesTheLoadAsTheHandSolution) {
  const double p = 1.0;  // v ~ 6e-6 m: linear range (mirror symmetry in y: no 2nd-order terms)
  const double iz = kRailHeight * std::pow(kRailWidth, 3) / 12;
  for (const std::string formulation : {"paper", "energy"}) {
    for (const double e : {0.0, 0.05}) {
      const Model model = testing::scene_from_json(two_rails(formulation, p, e));
      ASSERT_EQ(model.rails.size(), 2u);
      ASSERT_EQ(model.beams.size(), 1u);
      Data data(model);
      const Solution s = solve(model, data);
      ASSERT_TRUE(s.result.ok) << s.result.message;

      // (i) The tangent at the solution is regular: redundant guides do not make it singular.
      compute_tangent(model, data, std::numeric_limits<double>::infinity(), false);
      const Eigen::MatrixXd k = -Eigen::MatrixXd(stiffness_matrix(model, data));
      const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(k).singularValues();
      const double ratio = sv.minCoeff() / sv.maxCoeff();
      std::printf(
          "%s, e = %.2f m: %d iterations, singular directions %d, tangent sigma_min / sigma_max "
          "= %.3e (%.3e / %.3e)\n",
          formulation.c_str(), e, s.result.iterations, s.result.singular_directions, ratio,
          sv.minCoeff(), sv.maxCoeff());
      EXPECT_EQ(s.result.singular_directions, 0);
      EXPECT_GT(ratio, 1e-14);

      // (ii) Each rail's reaction against the hand solution. The rails' torsion constant is the
      // model's rectangle value (model.rails[i].gj / G: the series solution, no closed form); the
      // drive rod is included as a third cantilever at z = 0 with its tiny bending and torsion
      // stiffness (E and G times 1e-16 m^4), which carries ~1e-8 of the load.
      const std::vector<Member> members{{-kS, kE * iz, model.rails[0].gj},
                                        {kS, kE * iz, model.rails[1].gj},
                                        {0.0, kE * kRodI, kG * kRodI}};
      const HandSolution h = hand_solution(members, kA, p, e);
      // Measured end forces: rail_end_forces(...).end2 is the force the carriage exerts ON the rail
      // at its tip, in the rail frame, which is global here (ground-fixed, x along x, y along y):
      // exactly the F_i, Mz_i, Mx_i of the hand solution. The load pushes the carriage down, so
      // the carriage pushes the rails down: fy < 0, and end1 fy = -end2 fy (the ground holds up).
      const std::vector<EndForces> ends{rail_end_forces(model, data, 0),
                                        rail_end_forces(model, data, 1),
                                        beam_end_forces(model, data, 0)};
      const char* names[] = {"left rail (z = -s)", "right rail (z = +s)", "drive rod"};
      double worst = 0;
      for (int i = 0; i < 3; ++i) {
        const Vec6& f = ends[i].end2;
        const double err =
            std::max({scaled(f(1), h.forces[i].fy, p), scaled(f(5), h.forces[i].mz, p * kA),
                      scaled(f(3), h.forces[i].mx, p * kA)});
        worst = std::max(worst, err);
        std::printf(
            "  %-20s end2 fy % .12e N (hand % .12e), mz % .6e, mx % .6e N m (hand % .6e, % .6e); "
            "end1 fy % .6e; error %.1e\n",
            names[i], f(1), h.forces[i].fy, f(5), f(3), h.forces[i].mz, h.forces[i].mx,
            ends[i].end1(1), err);
      }
      const double e_v = scaled(s.displacement(1), h.v, std::abs(h.v));
      const double e_tz = scaled(s.rotation(2), h.theta_z, std::abs(h.theta_z));
      // psi vanishes for e = 0; compare it with the rotation scale theta_z then.
      const double e_psi =
          scaled(s.rotation(0), h.psi, std::max(std::abs(h.psi), std::abs(h.theta_z)));
      std::printf(
          "  carriage: v % .12e m (hand % .12e), theta_z % .12e (hand % .12e), psi % .12e (hand "
          "% .12e); errors %.1e %.1e %.1e; slide dx %.1e m\n",
          s.displacement(1), h.v, s.rotation(2), h.theta_z, s.rotation(0), h.psi, e_v, e_tz, e_psi,
          s.displacement(0));
      EXPECT_LT(worst, 1e-8);
      EXPECT_LT(e_v, 1e-8);
      EXPECT_LT(e_tz, 1e-8);
      EXPECT_LT(e_psi, 1e-8);
      // The sign convention: the rails are pushed down, the ground holds them up.
      EXPECT_LT(ends[0].end2(1), 0.0);
      EXPECT_LT(ends[1].end2(1), 0.0);
      EXPECT_NEAR(ends[0].end1(1), -ends[0].end2(1), 1e-12 * p);
      if (e == 0.0) {
        // Symmetric: the two rails share equally (all but the rod's ~1e-8 share), no twist.
        EXPECT_NEAR(ends[0].end2(1), ends[1].end2(1), 1e-12 * p);
        EXPECT_NEAR(ends[0].end2(1), -p / 2, 1e-7 * p);
        EXPECT_LT(std::abs(s.rotation(0)), 1e-12 * std::abs(s.rotation(2)));
      } else {
        // Off-centre towards +z: the right rail carries more.
        EXPECT_LT(ends[1].end2(1), ends[0].end2(1));
      }
    }
  }
}

}  // namespace
}  // namespace beamrail
