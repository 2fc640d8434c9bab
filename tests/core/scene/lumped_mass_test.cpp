// The mass of unsegmented elements with a density (docs/model.md "Mass"): a beam carries it as one
// segment, half at each free end body; a rail carries it wholly on body 1 (the rail's body, along
// which the carriage slides) as a rod between its points; fixed bodies take none. The dynamics
// then see the mass the mass response counts.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/analysis/modal_analysis.hpp"
#include "tests/support/scene_builder.hpp"

namespace beamrail {
namespace {

using testing::body_index;
using testing::Scene;
constexpr double kE = 2.1e11, kG = 8.0769e10, kRho = 7850.0;

// Total mass and first moment of the free bodies.
double free_mass(const Model& m) {
  double total = 0.0;
  for (int i : m.free_bodies) total += m.bodies[i].mass;
  return total;
}

// A 2 m steel beam of 20 mm square section between two free 1 kg bodies.
Scene two_bodies(int segments) {
  Scene s;
  s.material("steel", kE, kG, kRho).square("sq", 0.02);
  s.body("a", 1.0, Vec3(1e-3, 2e-3, 3e-3), Vec3(0, 0, 0));
  s.body("b", 1.0, Vec3(1e-3, 2e-3, 3e-3), Vec3(2, 0, 0));
  s.beam("link", "a", "b", Vec3(0, 0, 0), Vec3(2, 0, 0), "steel", "sq");
  if (segments > 0) s.last_beam()["segments"] = segments;
  return s;
}

TEST(LumpedMass, AnUnsegmentedBeamPutsHalfItsMassOnEachFreeEnd) {
  const Model m = two_bodies(0).model();
  const double beam = kRho * 0.02 * 0.02 * 2.0;  // 6.28 kg
  EXPECT_NEAR(m.bodies[body_index(m, "a")].mass, 1.0 + beam / 2, 1e-12);
  EXPECT_NEAR(m.bodies[body_index(m, "b")].mass, 1.0 + beam / 2, 1e-12);
  EXPECT_NEAR(free_mass(m), 2.0 + beam, 1e-12);
  // The halves sit at the attachment points (the bodies' centres here): no centre moves. The
  // half beam's rotary inertia about the end, in element axes: the slice's own rho a (Iy + Iz)
  // axially; m_h a^2 / 12 + m_h (a / 2)^2 = m_h a^2 / 3 (a = L / 2) plus rho a I across.
  const Body& a = m.bodies[body_index(m, "a")];
  EXPECT_EQ(a.position, Vec3(0, 0, 0));
  const double half = beam / 2, len = 1.0, i = 0.02 * 0.02 * 0.02 * 0.02 / 12;
  EXPECT_NEAR(a.inertia(0, 0), 1e-3 + kRho * len * 2 * i, 1e-12);
  EXPECT_NEAR(a.inertia(1, 1), 2e-3 + kRho * len * i + half * len * len / 3, 1e-12);
  EXPECT_NEAR(a.inertia(2, 2), 3e-3 + kRho * len * i + half * len * len / 3, 1e-12);
}

TEST(LumpedMass, AnUnsegmentedBeamIsOneSegment) {
  const Model zero = two_bodies(0).model(), one = two_bodies(1).model();
  ASSERT_EQ(zero.bodies.size(), one.bodies.size());
  for (size_t i = 0; i < zero.bodies.size(); ++i) {
    EXPECT_EQ(zero.bodies[i].mass, one.bodies[i].mass) << i;
    EXPECT_EQ(zero.bodies[i].inertia, one.bodies[i].inertia) << i;
    EXPECT_EQ(zero.bodies[i].position, one.bodies[i].position) << i;
  }
}

// The mass off the centre moves the body's centre to the combined one.
TEST(LumpedMass, MassAtAnOffsetPointMovesTheCentre) {
  Scene s;
  s.material("steel", kE, kG, kRho).square("sq", 0.02);
  s.body("tip", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(1.1, 0, 0));
  s.beam("arm", "ground", "tip", Vec3(0, 0, 0), Vec3(1, 0, 0), "steel", "sq");
  const Model m = s.model();
  const double half = kRho * 0.02 * 0.02 * 1.0 / 2;  // 1.57 kg at x = 1
  const Body& tip = m.bodies[body_index(m, "tip")];
  EXPECT_NEAR(tip.mass, 1.0 + half, 1e-12);
  EXPECT_NEAR(tip.position.x(), (1.0 * 1.1 + half * 1.0) / (1.0 + half), 1e-12);
  EXPECT_NEAR(free_mass(m), 1.0 + half, 1e-12);  // the ground's half goes nowhere
}

// A rail's mass rides on its body 1 (as a rod between its points), never on the carriage.
TEST(LumpedMass, ARailsMassIsOnItsBodyNotOnTheCarriage) {
  Scene s;
  s.material("steel", kE, kG, kRho).circle("rod", 0.02);
  s.body("frame", 2.0, Vec3(1e-2, 1e-2, 1e-2), Vec3(0.25, 0, 0));
  s.body("carriage", 1.0, Vec3(1e-3, 1e-3, 1e-3), Vec3(0.5, 0, 0));
  s.beam("post", "ground", "frame", Vec3(0, 0, 0), Vec3(0.25, 0, 0), "stiff", "rod");
  s.material("stiff", kE, kG);
  s.rail("guide", "prismatic", "frame", "carriage", Vec3(0, 0, 0), Vec3(0.5, 0, 0), "steel", "rod");
  const Model m = s.model();
  const double rail = kRho * std::numbers::pi * 0.01 * 0.01 * 0.5;  // 1.23 kg, centre x = 0.25
  const Body& frame = m.bodies[body_index(m, "frame")];
  const Body& carriage = m.bodies[body_index(m, "carriage")];
  EXPECT_NEAR(frame.mass, 2.0 + rail, 1e-12);
  EXPECT_EQ(frame.position, Vec3(0.25, 0, 0));
  // About the frame's centre (the rod's too), across the rod: m l^2 / 12 + rho l I.
  const double i = std::numbers::pi * std::pow(0.02, 4) / 64;
  EXPECT_NEAR(frame.inertia(1, 1), 1e-2 + rail * 0.25 / 12 + kRho * 0.5 * i, 1e-12);
  EXPECT_EQ(carriage.mass, 1.0);
  EXPECT_EQ(carriage.inertia, Mat3(Vec3(1e-3, 1e-3, 1e-3).asDiagonal()));
}

// A cantilever of three 0.5 m members (joint bodies of 0.1 kg, a 0.5 kg tip; the members carry
// 4.7 kg): f1 with the members unsegmented (their mass lumped at the joints) against the
// converged distributed-mass value (16 segments per member), and against massless members (the
// mass response counted them, the dynamics did not: the old behaviour).
TEST(LumpedMass, LumpedMassesTrackTheDistributedMassFrequency) {
  const auto f1 = [](int segments, bool density) {
    Scene s;
    if (density)
      s.material("steel", kE, kG, kRho);
    else
      s.material("steel", kE, kG);
    s.square("sq", 0.02);
    s.body("j1", 0.1, Vec3(1e-5, 1e-5, 1e-5), Vec3(0.5, 0, 0));
    s.body("j2", 0.1, Vec3(1e-5, 1e-5, 1e-5), Vec3(1.0, 0, 0));
    s.body("tip", 0.5, Vec3(1e-4, 1e-4, 1e-4), Vec3(1.5, 0, 0));
    s.beam("m1", "ground", "j1", Vec3(0, 0, 0), Vec3(0.5, 0, 0), "steel", "sq");
    s.beam("m2", "j1", "j2", Vec3(0.5, 0, 0), Vec3(1.0, 0, 0), "steel", "sq");
    s.beam("m3", "j2", "tip", Vec3(1.0, 0, 0), Vec3(1.5, 0, 0), "steel", "sq");
    for (Json& b : s.j["beams"])
      if (segments > 0) b["segments"] = segments;
    const Model m = s.model();
    Data data(m);
    ModalOptions options;
    options.modes = 1;
    const ModalResult r = solve_modal(m, options, data);
    EXPECT_TRUE(r.ok) << r.message;
    return r.ok ? elastic_mode(r, 1)->frequency_hz : NAN;
  };
  const double converged = f1(16, true), lumped = f1(0, true), massless = f1(0, false);
  std::printf(
      "f1: distributed (16 segments per member) %.4f Hz, lumped %.4f Hz (%+.2f %%), "
      "massless members %.4f Hz (%+.1f %%)\n",
      converged, lumped, 100 * (lumped / converged - 1), massless,
      100 * (massless / converged - 1));
  // Lumping at the joints puts mass farther out than it is: a lower frequency, and at most a
  // tenth of the error of massless members.
  EXPECT_LT(lumped, converged);
  EXPECT_LT(std::abs(lumped / converged - 1), 0.1 * std::abs(massless / converged - 1));
}

}  // namespace
}  // namespace beamrail
