// A 3-D frame of five free bodies and nine beams against an independent direct-stiffness assembly
// written here: the standard 12 x 12 Euler-Bernoulli space-frame matrix of each beam in its local
// frame, rotated to global axes, carried to the bodies' centres by rigid links, and assembled into
// a 6n x 6n stiffness; the mass matrix is blockdiag(m I, A J A^T). Static displacements, all 6n
// frequencies and the model's tangent stiffness at the initial configuration must agree with it.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "core/model/rotation.hpp"
#include "tests/support/scenes.hpp"

namespace beamrail {
namespace {

constexpr double kPi = std::numbers::pi;

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

std::string vec(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.17g, %.17g, %.17g]", v(0), v(1), v(2));
  return buf;
}

struct Material {
  double e, g;
};
const std::map<std::string, Material> kMaterials{{"steel", {2.1e11, 8.0769e10}},
                                                 {"alu", {7.0e10, 2.6e10}}};

// Section properties computed here from the textbook formulas (width along local y, height along
// local z), except the rectangle's torsion constant, which has no closed form: for it the test uses
// the value the model uses (model.beams[i].gj / G), so both sides describe the same beam.
struct Section {
  std::string json;
  double area, iy, iz, ix;  // ix: 0 when it must come from the model (rectangle)
};
Section rectangle(double w, double h) {
  char buf[128];
  std::snprintf(buf, sizeof buf, R"({"shape": "rectangle", "width": %.17g, "height": %.17g})", w,
                h);
  return {buf, w * h, w * h * h * h / 12, h * w * w * w / 12, 0.0};
}
Section tube(double d, double t) {
  char buf[128];
  std::snprintf(buf, sizeof buf, R"({"shape": "tube", "outer_diameter": %.17g, "wall": %.17g})", d,
                t);
  const double di = d - 2 * t, i = kPi * (std::pow(d, 4) - std::pow(di, 4)) / 64;
  return {buf, kPi * (d * d - di * di) / 4, i, i, 2 * i};
}
Section circle(double d) {
  char buf[128];
  std::snprintf(buf, sizeof buf, R"({"shape": "circle", "diameter": %.17g})", d);
  const double i = kPi * std::pow(d, 4) / 64;
  return {buf, kPi * d * d / 4, i, i, 2 * i};
}
const std::map<std::string, Section> kSections{{"rect", rectangle(0.012, 0.02)},
                                               {"flat", rectangle(0.025, 0.01)},
                                               {"tube", tube(0.03, 0.003)},
                                               {"rod", circle(0.016)}};

struct BodySpec {
  std::string name;
  double mass;
  std::array<double, 6> inertia;  // body axes: xx, yy, zz, xy, xz, yz
  Vec3 position;
  Vec4 orientation;  // normalized before use
};

struct BeamSpec {
  std::string name, body1, body2;
  Vec3 p1, p2, p3;
  std::string material, section;
};

// Five bodies with full inertia tensors, four of them rotated; nine beams in skew directions, three
// of them to ground, most attached away from the bodies' centres.
const std::vector<BodySpec> kBodies{
    {"a", 2.5, {0.04, 0.05, 0.06, 0.004, -0.003, 0.002}, {0.3, 0.1, 0.4}, {0.9, 0.1, -0.3, 0.2}},
    {"b", 1.8, {0.02, 0.03, 0.035, -0.002, 0.001, 0.003}, {0.9, -0.2, 0.5}, {1, 0, 0, 0}},
    {"c", 4.0, {0.08, 0.06, 0.09, 0.01, 0.005, -0.004}, {0.7, 0.5, 1.0}, {0.7, 0.5, 0.3, -0.4}},
    {"d", 1.2, {0.015, 0.02, 0.018, 0.001, -0.002, -0.001}, {0.2, 0.6, 0.9}, {0.95, 0, 0.3, 0}},
    {"e", 3.1, {0.05, 0.07, 0.04, -0.006, 0.004, 0.002}, {1.2, 0.3, 0.2}, {0.6, -0.2, 0.5, 0.6}}};

const std::vector<BeamSpec> kBeams{
    {"g_a", "ground", "a", {0, 0, 0}, {0.25, 0.05, 0.35}, {0.1, 0.3, -0.2}, "steel", "rect"},
    {"g_e", "ground", "e", {1.4, 0, -0.2}, {1.25, 0.28, 0.15}, {1.5, 0.2, 0.3}, "alu", "flat"},
    {"g_d", "ground", "d", {-0.2, 0.8, 1.1}, {0.18, 0.62, 0.92}, {-0.1, 0.5, 1.3}, "alu", "rod"},
    {"a_b", "a", "b", {0.35, 0.1, 0.45}, {0.85, -0.15, 0.5}, {0.5, 0.1, 0.9}, "steel", "tube"},
    {"b_c", "b", "c", {0.9, -0.15, 0.55}, {0.72, 0.45, 0.95}, {1.2, 0.2, 0.5}, "alu", "rod"},
    {"c_d", "c", "d", {0.65, 0.5, 1.0}, {0.25, 0.6, 0.88}, {0.4, 0.3, 1.3}, "steel", "rect"},
    {"d_a", "d", "a", {0.2, 0.55, 0.85}, {0.3, 0.15, 0.45}, {0.0, 0.2, 0.7}, "alu", "flat"},
    {"b_e", "b", "e", {0.95, -0.2, 0.45}, {1.15, 0.3, 0.25}, {1.0, 0.4, 0.6}, "steel", "tube"},
    {"e_c", "e", "c", {1.2, 0.35, 0.25}, {0.75, 0.5, 0.95}, {1.3, 0.7, 0.8}, "steel", "rect"}};

struct LoadSpec {
  bool force;  // false: torque
  std::string body;
  Vec3 point;  // forces only: global point of application
  Vec3 value;
};
// Unit-scale loads; the test scales them so that the largest displacement is ~1e-7 m.
const std::vector<LoadSpec> kLoads{{true, "a", {0.32, 0.13, 0.37}, {3, -2, 5}},
                                   {false, "b", {}, {0.4, 0.7, -0.3}},
                                   {true, "c", {0.75, 0.45, 1.04}, {-4, 1, 2}},
                                   {true, "e", {1.17, 0.33, 0.24}, {1, 6, -2}},
                                   {false, "d", {}, {-0.5, 0.2, 0.6}}};

Mat3 inertia_tensor(const BodySpec& b) {
  const auto& j = b.inertia;
  Mat3 t;
  t << j[0], j[3], j[4], j[3], j[1], j[5], j[4], j[5], j[2];
  return t;
}

std::string scene(const std::string& formulation, double load_scale) {
  std::string s = R"({"materials": {)";
  bool first = true;
  for (const auto& [name, m] : kMaterials) {
    s += (first ? "" : ", ") +
         ("\"" + name + "\": {\"E\": " + num(m.e) + ", \"G\": " + num(m.g) + "}");
    first = false;
  }
  s += R"(}, "sections": {)";
  first = true;
  for (const auto& [name, sec] : kSections) {
    s += (first ? "\"" : ", \"") + name + "\": " + sec.json;
    first = false;
  }
  s += R"(}, "bodies": [)";
  for (size_t i = 0; i < kBodies.size(); ++i) {
    const BodySpec& b = kBodies[i];
    const Vec4 q = b.orientation.normalized();
    std::string inertia;
    for (int k = 0; k < 6; ++k) inertia += (k ? ", " : "") + num(b.inertia[k]);
    s += (i ? ", " : "") + std::string(R"({"name": ")") + b.name + R"(", "mass": )" + num(b.mass) +
         R"(, "inertia": [)" + inertia + R"(], "position": )" + vec(b.position) +
         R"(, "orientation": [)" + num(q(0)) + ", " + num(q(1)) + ", " + num(q(2)) + ", " +
         num(q(3)) + "]}";
  }
  s += R"(], "beams": [)";
  for (size_t i = 0; i < kBeams.size(); ++i) {
    const BeamSpec& e = kBeams[i];
    s += (i ? ", " : "") + std::string(R"({"name": ")") + e.name + R"(", "body1": ")" + e.body1 +
         R"(", "body2": ")" + e.body2 + R"(", "point1": )" + vec(e.p1) + R"(, "point2": )" +
         vec(e.p2) + R"(, "point3": )" + vec(e.p3) + R"(, "material": ")" + e.material +
         R"(", "section": ")" + e.section + R"(", "formulation": ")" + formulation + "\"}";
  }
  s += R"(], "loads": [)";
  for (size_t i = 0; i < kLoads.size(); ++i) {
    const LoadSpec& l = kLoads[i];
    s += (i ? ", " : "") + std::string(R"({"type": ")") + (l.force ? "force" : "torque") +
         R"(", "body": ")" + l.body + "\"" + (l.force ? ", \"point\": " + vec(l.point) : "") +
         R"(, "value": )" + vec(load_scale * l.value) + "}";
  }
  return s + "]}";
}

int body_index(const std::string& name) {
  for (size_t i = 0; i < kBodies.size(); ++i)
    if (kBodies[i].name == name) return static_cast<int>(i);
  return -1;  // ground
}

// The standard 12 x 12 space-frame stiffness in the local frame, DOFs (u, v, w, tx, ty, tz) of end
// 1 then end 2: axial E S / l, torsion G Ix / l, bending in x-y (v, tz) with E Iz, bending in x-z
// (w, ty) with E Iy (ty = -dw/dx, hence the opposite signs of the coupling terms).
Eigen::Matrix<double, 12, 12> local_stiffness(double ea, double gj, double eiy, double eiz,
                                              double l) {
  Eigen::Matrix<double, 12, 12> k = Eigen::Matrix<double, 12, 12>::Zero();
  const auto pair = [&](int i, int j, double value) {
    k(i, j) += value;
    if (i != j) k(j, i) += value;
  };
  pair(0, 0, ea / l), pair(6, 6, ea / l), pair(0, 6, -ea / l);
  pair(3, 3, gj / l), pair(9, 9, gj / l), pair(3, 9, -gj / l);
  const double l2 = l * l, l3 = l2 * l;
  // x-y plane: v1 = 1, tz1 = 5, v2 = 7, tz2 = 11.
  pair(1, 1, 12 * eiz / l3), pair(7, 7, 12 * eiz / l3), pair(1, 7, -12 * eiz / l3);
  pair(1, 5, 6 * eiz / l2), pair(1, 11, 6 * eiz / l2);
  pair(5, 7, -6 * eiz / l2), pair(7, 11, -6 * eiz / l2);
  pair(5, 5, 4 * eiz / l), pair(11, 11, 4 * eiz / l), pair(5, 11, 2 * eiz / l);
  // x-z plane: w1 = 2, ty1 = 4, w2 = 8, ty2 = 10.
  pair(2, 2, 12 * eiy / l3), pair(8, 8, 12 * eiy / l3), pair(2, 8, -12 * eiy / l3);
  pair(2, 4, -6 * eiy / l2), pair(2, 10, -6 * eiy / l2);
  pair(4, 8, 6 * eiy / l2), pair(8, 10, 6 * eiy / l2);
  pair(4, 4, 4 * eiy / l), pair(10, 10, 4 * eiy / l), pair(4, 10, 2 * eiy / l);
  return k;
}

struct Reference {
  Eigen::MatrixXd k, m;
  Eigen::VectorXd f;  // generalized load vector for load_scale 1
};

// The independent assembly. Only the rectangle torsion constants come from the model (see Section).
Reference assemble(const Model& model) {
  const int n = 6 * static_cast<int>(kBodies.size());
  Reference ref{Eigen::MatrixXd::Zero(n, n), Eigen::MatrixXd::Zero(n, n), Eigen::VectorXd::Zero(n)};
  for (size_t i = 0; i < kBeams.size(); ++i) {
    const BeamSpec& b = kBeams[i];
    const Material& mat = kMaterials.at(b.material);
    const Section& sec = kSections.at(b.section);
    const double ix = sec.ix > 0 ? sec.ix : model.beams[i].gj / mat.g;
    const Vec3 d = b.p2 - b.p1;
    const double l = d.norm();
    Mat3 r;  // local -> global: columns x, y, z
    r.col(0) = d / l;
    const Vec3 off = b.p3 - b.p1;
    r.col(1) = (off - off.dot(r.col(0)) * r.col(0)).normalized();
    r.col(2) = r.col(0).cross(r.col(1));
    const Eigen::Matrix<double, 12, 12> kl =
        local_stiffness(mat.e * sec.area, mat.g * ix, mat.e * sec.iy, mat.e * sec.iz, l);
    // Global DOFs of the ends -> local: blockdiag(R^T, R^T, R^T, R^T).
    Eigen::Matrix<double, 12, 12> t = Eigen::Matrix<double, 12, 12>::Zero();
    for (int k = 0; k < 4; ++k) t.block<3, 3>(3 * k, 3 * k) = r.transpose();
    const Eigen::Matrix<double, 12, 12> kg = t.transpose() * kl * t;
    // Rigid links: end displacement dc + dtheta x rho = dc - [rho]x dtheta, end rotation dtheta,
    // rho = attachment point - body centre (initial configuration, global).
    const std::array<int, 2> body{body_index(b.body1), body_index(b.body2)};
    const std::array<Vec3, 2> point{b.p1, b.p2};
    std::array<Eigen::Matrix<double, 6, 6>, 2> link;
    for (int e = 0; e < 2; ++e) {
      link[e].setIdentity();
      if (body[e] >= 0)
        link[e].block<3, 3>(0, 3) = -skew<double>(Vec3(point[e] - kBodies[body[e]].position));
    }
    for (int a = 0; a < 2; ++a)
      for (int c = 0; c < 2; ++c) {
        if (body[a] < 0 || body[c] < 0) continue;
        ref.k.block<6, 6>(6 * body[a], 6 * body[c]) +=
            link[a].transpose() * kg.block<6, 6>(6 * a, 6 * c) * link[c];
      }
  }
  for (size_t i = 0; i < kBodies.size(); ++i) {
    const BodySpec& b = kBodies[i];
    const Mat3 a = rotation_matrix<double>(b.orientation);
    ref.m.block<3, 3>(6 * i, 6 * i) = b.mass * Mat3::Identity();
    ref.m.block<3, 3>(6 * i + 3, 6 * i + 3) = a * inertia_tensor(b) * a.transpose();
  }
  for (const LoadSpec& l : kLoads) {
    const int i = body_index(l.body);
    if (l.force) {
      ref.f.segment<3>(6 * i) += l.value;
      ref.f.segment<3>(6 * i + 3) += (l.point - kBodies[i].position).cross(l.value);
    } else {
      ref.f.segment<3>(6 * i + 3) += l.value;
    }
  }
  return ref;
}

// The model's free bodies are in scene order; check it so the DOF maps agree.
void expect_body_order(const Model& model) {
  ASSERT_EQ(model.n_free(), static_cast<int>(kBodies.size()));
  for (size_t i = 0; i < kBodies.size(); ++i)
    ASSERT_EQ(model.bodies[model.free_bodies[i]].name, kBodies[i].name);
}

class Frame : public ::testing::TestWithParam<std::string> {};

// Displacements and rotation vectors (of A A0^T) of the free bodies at static equilibrium.
Eigen::VectorXd static_solution(const Model& model, StaticResult* result) {
  Data data(model);
  StaticOptions options;
  options.tolerance = 1e-13;
  *result = solve_static(model, options, data);
  Eigen::VectorXd x(model.n_dofs);
  for (int k = 0; k < model.n_free(); ++k) {
    const int b = model.free_bodies[k];
    x.segment<3>(6 * k) = data.pose[b].u;
    x.segment<3>(6 * k + 3) = rotation_vector(
        Mat3(data.pose[b].A * rotation_matrix<double>(model.bodies[b].orientation).transpose()));
  }
  return x;
}

// The stiffness of the loads d(load wrench)/d(dc, dtheta): a force F at a point R = A r from the
// centre that moves with the body has the moment R x F, whose change under dtheta is
// (dtheta x R) x F = [F]x [R]x dtheta.
Eigen::MatrixXd load_stiffness(double scale) {
  const int n = 6 * static_cast<int>(kBodies.size());
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n, n);
  for (const LoadSpec& l : kLoads) {
    if (!l.force) continue;
    const int i = body_index(l.body);
    k.block<3, 3>(6 * i + 3, 6 * i + 3) +=
        skew<double>(Vec3(scale * l.value)) * skew<double>(Vec3(l.point - kBodies[i].position));
  }
  return k;
}

// The tangent at the initial configuration: unloaded it is the assembled K; loaded, the point loads
// that move with the bodies add their own stiffness (load_stiffness), and nothing else changes
// since the beams are still undeformed.
TEST_P(Frame, TangentAtTheInitialConfigurationIsTheAssembledStiffness) {
  for (const double load_scale : {0.0, 1.0}) {
    const Model model = testing::scene_from_json(scene(GetParam(), load_scale));
    expect_body_order(model);
    const Reference ref = assemble(model);
    Data data(model);
    compute_tangent(model, data, std::numeric_limits<double>::infinity(), false);
    const Eigen::MatrixXd k = -Eigen::MatrixXd(stiffness_matrix(model, data));
    const Eigen::MatrixXd expected = ref.k - load_stiffness(load_scale);
    const double scale = expected.cwiseAbs().maxCoeff();
    const double diff = (k - expected).cwiseAbs().maxCoeff();
    const Eigen::MatrixXd mass(mass_matrix(model, data));
    const double mass_diff = (mass - ref.m).cwiseAbs().maxCoeff() / ref.m.cwiseAbs().maxCoeff();
    std::printf(
        "%s, %s: tangent vs assembled K: max |difference| %.3e of max entry %.3e (%.2e "
        "relative); mass matrix %.2e relative\n",
        GetParam().c_str(), load_scale == 0 ? "unloaded" : "loaded (load stiffness added)", diff,
        scale, diff / scale, mass_diff);
    EXPECT_LT(diff, 1e-10 * scale);
    EXPECT_LT(mass_diff, 1e-14);
  }
}

struct Errors {
  double max_u = 0, max_r = 0, err_u = 0, err_r = 0;
};
Errors compare(const Eigen::VectorXd& x, const Eigen::VectorXd& expected) {
  Errors e;
  for (int i = 0; i < x.size(); ++i) {
    const double d = std::abs(x(i) - expected(i));
    if (i % 6 < 3) {
      e.max_u = std::max(e.max_u, std::abs(expected(i)));
      e.err_u = std::max(e.err_u, d);
    } else {
      e.max_r = std::max(e.max_r, std::abs(expected(i)));
      e.err_r = std::max(e.err_r, d);
    }
  }
  return e;
}

// The static check. The model is geometrically nonlinear, and in a frame whose beams attach away
// from the bodies' centres the second-order terms are of relative size ~ the rotations (a body
// turning by theta turns its lever arms, R -> R + theta x R; the point loads follow the bodies the
// same way): measured, |x - K^-1 f| / |x| = 0.5 to 1 x (max displacement / 1 m), i.e. 5e-8 to 1e-7
// at displacements of 1e-7 m, while rounding of the absolute coordinates (~1e-16 m) rules out much
// smaller loads. So the linear response is isolated exactly by solving under +f and -f: the
// antisymmetric part (x(f) - x(-f)) / 2 = K^-1 f + O(f^3) has no second-order terms. That part must
// agree with the assembly to 1e-8; the direct difference must be second order (10 times the load:
// 10 times the relative difference), which a wrong linear stiffness would not be.
TEST_P(Frame, StaticDisplacementsMatchTheDirectStiffnessSolution) {
  const Model unit = testing::scene_from_json(scene(GetParam(), 1.0));
  expect_body_order(unit);
  const Reference ref = assemble(unit);
  const Eigen::VectorXd x_unit = ref.k.ldlt().solve(ref.f);
  double unit_max = 0;
  for (int i = 0; i < x_unit.size(); ++i)
    if (i % 6 < 3) unit_max = std::max(unit_max, std::abs(x_unit(i)));
  double direct[2];
  for (int level = 0; level < 2; ++level) {
    // Largest displacement 1e-6 m, then 1e-5 m (the frame is ~1.6 m across).
    const double target = level == 0 ? 1e-6 : 1e-5, load_scale = target / unit_max;
    StaticResult plus, minus;
    const Eigen::VectorXd x =
        static_solution(testing::scene_from_json(scene(GetParam(), load_scale)), &plus);
    const Eigen::VectorXd x_minus =
        static_solution(testing::scene_from_json(scene(GetParam(), -load_scale)), &minus);
    ASSERT_TRUE(plus.ok) << plus.message;
    ASSERT_TRUE(minus.ok) << minus.message;
    EXPECT_EQ(plus.singular_directions, 0);
    const Eigen::VectorXd expected = load_scale * x_unit;
    const Errors d = compare(x, expected), a = compare(0.5 * (x - x_minus), expected);
    direct[level] = std::max(d.err_u / d.max_u, d.err_r / d.max_r);
    std::printf(
        "%s: static, max displacement %.3e m, max rotation %.3e rad (%d + %d iterations, "
        "residuals %.1e, %.1e N)\n"
        "  (x(f) - x(-f))/2 vs K^-1 f: displacements %.3e m worst (%.2e relative), rotations "
        "%.3e rad worst (%.2e relative)\n"
        "  x(f) vs K^-1 f (second-order terms included): %.2e relative\n",
        GetParam().c_str(), d.max_u, d.max_r, plus.iterations, minus.iterations, plus.residual_norm,
        minus.residual_norm, a.err_u, a.err_u / a.max_u, a.err_r, a.err_r / a.max_r, direct[level]);
    EXPECT_LT(a.err_u, 1e-8 * a.max_u);
    EXPECT_LT(a.err_r, 1e-8 * a.max_r);
  }
  std::printf("%s: direct difference grows %.4f times for 10 times the load\n", GetParam().c_str(),
              direct[1] / direct[0]);
  EXPECT_NEAR(direct[1] / direct[0], 10.0, 0.1);
}

TEST_P(Frame, AllFrequenciesMatchTheDirectStiffnessEigenproblem) {
  const Model model = testing::scene_from_json(scene(GetParam(), 0.0));
  expect_body_order(model);
  const Reference ref = assemble(model);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(ref.k, ref.m);
  ASSERT_EQ(eig.info(), Eigen::Success);
  Data data(model);
  ModalOptions options;
  options.modes = model.n_dofs;
  options.solver = EigenSolverKind::kDense;
  const ModalResult r = solve_modal(model, options, data);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.rigid_modes, 0);
  ASSERT_EQ(static_cast<int>(r.modes.size()), model.n_dofs);
  double worst = 0;
  for (int i = 0; i < model.n_dofs; ++i) {
    const double f = std::sqrt(eig.eigenvalues()(i)) / (2 * kPi);
    const double err = std::abs(r.modes[i].frequency_hz / f - 1);
    worst = std::max(worst, err);
    EXPECT_EQ(r.modes[i].kind, Mode::Kind::kElastic) << "mode " << i + 1;
    EXPECT_LT(err, 1e-8) << "mode " << i + 1;
  }
  std::printf("%s: %d frequencies %.4f .. %.4f Hz, worst relative difference %.2e\n",
              GetParam().c_str(), model.n_dofs, r.modes.front().frequency_hz,
              r.modes.back().frequency_hz, worst);
}

INSTANTIATE_TEST_SUITE_P(Formulations, Frame, ::testing::Values("energy", "paper"));

}  // namespace
}  // namespace beamrail
