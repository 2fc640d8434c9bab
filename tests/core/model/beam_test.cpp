// Property tests of the beam kernel (docs/model.md) on random configurations, both formulations.
#include "core/model/beam.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include "tests/support/random_elements.hpp"

namespace beamrail {
namespace {

using testing::Random;

struct Wrenches {
  Vec6 w1 = Vec6::Zero(), w2 = Vec6::Zero();
  double energy = 0.0;
};

Wrenches evaluate(const Beam& beam, const Pose<double>& b1, const Pose<double>& b2) {
  Wrenches w;
  w.energy = beam_wrenches(beam, b1, b2, w.w1, w.w2);
  return w;
}

// A random beam between two randomly placed bodies, undeformed in the returned poses.
struct BeamCase {
  Beam beam;
  Pose<double> b1, b2;
};

BeamCase random_case(Random& rng, Formulation formulation, double damping = 0.0) {
  BeamCase s;
  s.b1 = testing::pose(rng.vec3(1.0), rng.rotation());
  s.b2 = testing::pose(rng.vec3(1.0) + Vec3(2, 0, 0), rng.rotation());
  const Vec3 p1 = s.b1.u + rng.vec3(0.2);
  const Vec3 p2 = s.b2.u + rng.vec3(0.2);
  const Vec3 p3 = p1 + rng.vec3(1.0);
  s.beam.ends = testing::make_ends(p1, p2, p3, s.b1, s.b2);
  const double e = 2.1e11 * rng.uniform(0.5, 1.5), g = 8.1e10 * rng.uniform(0.5, 1.5);
  const double w = rng.uniform(0.005, 0.02), h = rng.uniform(0.005, 0.02);
  s.beam.ea = e * w * h;
  s.beam.gj = g * 0.14 * w * h * std::min(w, h) * std::min(w, h);
  s.beam.eiy = e * w * h * h * h / 12;
  s.beam.eiz = e * h * w * w * w / 12;
  s.beam.formulation = formulation;
  s.beam.damping = damping;
  return s;
}

// Moves both bodies rigidly by a large random motion, then deforms body 2 by (dc, theta).
void deform(Random& rng, BeamCase& s, double size) {
  const Mat3 rot = rng.rotation();
  const Vec3 shift = rng.vec3(3.0);
  s.b1 = testing::moved(s.b1, rot, shift);
  s.b2 = testing::moved(s.b2, rot, shift);
  s.b2 = testing::perturbed(s.b2, rng.vec3(size * s.beam.ends.length), rng.vec3(size));
}

const Formulation kBoth[] = {Formulation::kEnergy, Formulation::kPaper};
const char* name(Formulation f) { return f == Formulation::kEnergy ? "energy" : "paper"; }

TEST(Beam, ForcesBalanceAndMomentsBalanceLocally) {
  for (Formulation f : kBoth) {
    Random rng(10);
    double worst_force = 0, worst_moment = 0;
    for (int i = 0; i < 200; ++i) {
      BeamCase s = random_case(rng, f);
      deform(rng, s, 1e-2);
      const Wrenches w = evaluate(s.beam, s.b1, s.b2);
      const Vec3 f1 = w.w1.head<3>(), f2 = w.w2.head<3>();
      const double scale = f2.norm();
      ASSERT_GT(scale, 0.0);
      worst_force = std::max(worst_force, (f1 + f2).norm() / scale);
      // End moments about the attachment points, in the left-end frame.
      const ElementFrames<double> fr =
          element_frames(s.beam.ends, s.b1, s.b2, rotation_measure(s.beam));
      const Vec3 m1 = fr.E1.transpose() * (w.w1.tail<3>() - fr.R1.cross(f1));
      const Vec3 m2 = fr.E1.transpose() * (w.w2.tail<3>() - fr.R2.cross(f2));
      const Vec3 f2_local = fr.E1.transpose() * f2;
      // Energy: exact balance on the deformed lever xi; paper: K1, K2 balance on (l, 0, 0).
      const Vec3 lever = f == Formulation::kEnergy ? fr.xi : Vec3(s.beam.ends.length, 0, 0);
      const double moment_scale = m1.norm() + m2.norm() + lever.norm() * scale;
      worst_moment =
          std::max(worst_moment, (m1 + m2 + lever.cross(f2_local)).norm() / moment_scale);
    }
    std::printf("%s: worst |F1+F2|/|F| = %.2e, worst local moment balance = %.2e\n", name(f),
                worst_force, worst_moment);
    EXPECT_LT(worst_force, 1e-12) << name(f);
    EXPECT_LT(worst_moment, 1e-12) << name(f);
  }
}

TEST(Beam, EnergyFormulationConservesAngularMomentumExactly) {
  Random rng(11);
  for (int i = 0; i < 100; ++i) {
    BeamCase s = random_case(rng, Formulation::kEnergy);
    deform(rng, s, 3e-2);
    const Wrenches w = evaluate(s.beam, s.b1, s.b2);
    const Vec3 total = s.b1.u.cross(w.w1.head<3>()) + w.w1.tail<3>() +
                       s.b2.u.cross(w.w2.head<3>()) + w.w2.tail<3>();
    const double scale = w.w1.tail<3>().norm() + w.w2.tail<3>().norm() +
                         (s.b1.u.norm() + s.b2.u.norm()) * w.w1.head<3>().norm();
    EXPECT_LT(total.norm() / scale, 1e-12);
  }
}

// A beam twisted 2.5 rad between its ends (body 2 turned about the element axis): under the energy
// law phi is the pure twist (2.5, 0, 0) and the beam is inside its range, its wrenches a pure
// torque G Ix / l * 2.5 about the axis on each body (no force, no bending moment); the paper's
// angles give the same phi but are outside their range (1.5 rad).
TEST(Beam, TwistedBeyondAQuarterTurnTheEnergyLawSeesPureTwist) {
  Random rng(20);
  for (int i = 0; i < 20; ++i) {
    BeamCase s = random_case(rng, Formulation::kEnergy);
    const ElementFrames<double> f0 =
        element_frames(s.beam.ends, s.b1, s.b2, RotationMeasure::kRotationVector);
    const Vec3 axis = f0.E1.col(0);
    // Turn body 2 by 2.5 rad about the element axis through point 2.
    const Mat3 r = rotation_matrix<double>(quat_from_rotation_vector(2.5 * axis));
    const Vec3 p2 = s.b2.u + f0.R2;
    Pose<double> b2 = s.b2;
    b2.A = r * s.b2.A;
    b2.u = p2 - r * f0.R2;
    const ElementFrames<double> f =
        element_frames(s.beam.ends, s.b1, b2, RotationMeasure::kRotationVector);
    EXPECT_LT((f.phi - Vec3(2.5, 0, 0)).norm(), 1e-12) << f.phi.transpose();
    EXPECT_FALSE(beam_out_of_range(s.beam, f));
    const Wrenches w = evaluate(s.beam, s.b1, b2);
    const double torque = s.beam.gj / s.beam.ends.length * 2.5;
    EXPECT_LT(w.w1.head<3>().norm(), 1e-9 * torque);
    EXPECT_LT((w.w2.tail<3>() + torque * axis).norm(), 1e-9 * torque);
    EXPECT_LT((w.w1.tail<3>() - torque * axis - f.lever1.cross(w.w1.head<3>())).norm(),
              1e-9 * torque);
    Beam paper = s.beam;
    paper.formulation = Formulation::kPaper;
    const ElementFrames<double> fp = element_frames(paper.ends, s.b1, b2, rotation_measure(paper));
    EXPECT_NEAR(fp.phi(0), 2.5, 1e-12);
    EXPECT_TRUE(beam_out_of_range(paper, fp));
  }
}

// Local end vectors at small deformation equal K1 delta and K2 delta (delta as the kernel measures
// it, steps 3-4), and that delta equals the deformation imposed by moving body 2 (body 1 held).
TEST(Beam, ForcesEqualStiffnessTimesDeformationWhenSmall) {
  for (Formulation f : kBoth) {
    Random rng(13);
    double worst = 0, worst_delta = 0;
    for (int i = 0; i < 200; ++i) {
      BeamCase s = random_case(rng, f);
      const ElementFrames<double> fr0 =
          element_frames(s.beam.ends, s.b1, s.b2, rotation_measure(s.beam));
      const Vec3 dc = rng.vec3(1e-8 * s.beam.ends.length), theta = rng.vec3(1e-8);
      const Pose<double> b2 = testing::perturbed(s.b2, dc, theta);
      const Wrenches w = evaluate(s.beam, s.b1, b2);
      Vec6 imposed;
      imposed.head<3>() = fr0.E1.transpose() * (dc + theta.cross(fr0.R2));
      imposed.tail<3>() = fr0.E1.transpose() * theta;
      const ElementFrames<double> fr =
          element_frames(s.beam.ends, s.b1, b2, rotation_measure(s.beam));
      const Vec6 delta = beam_deformation(s.beam, fr);
      worst_delta = std::max(worst_delta, (delta - imposed).norm() / imposed.norm());
      const StiffnessBlocks<double> k(s.beam.ea, s.beam.gj, s.beam.eiy, s.beam.eiz,
                                      s.beam.ends.length);
      Vec6 p1, p2;  // what the beam exerts, in the left-end frame, moments about the ends
      p1 << fr.E1.transpose() * w.w1.head<3>(),
          fr.E1.transpose() * (w.w1.tail<3>() - fr.R1.cross(w.w1.head<3>()));
      p2 << fr.E1.transpose() * w.w2.head<3>(),
          fr.E1.transpose() * (w.w2.tail<3>() - fr.R2.cross(w.w2.head<3>()));
      const Vec6 k1 = k.k1(delta), k2 = k.k2(delta);
      worst = std::max(worst, (p1 + k1).norm() / k1.norm());
      worst = std::max(worst, (p2 + k2).norm() / k2.norm());
    }
    std::printf(
        "%s: deformation 1e-8: worst relative |P - K delta| = %.2e, |delta - imposed| = %.2e\n",
        name(f), worst, worst_delta);
    EXPECT_LT(worst, 1e-6) << name(f);
    EXPECT_LT(worst_delta, 1e-6) << name(f);
  }
}

TEST(Beam, DampingOnlyRemovesEnergy) {
  for (Formulation f : kBoth) {
    Random rng(16);
    for (int i = 0; i < 200; ++i) {
      BeamCase s = random_case(rng, f, rng.uniform(1e-5, 1e-2));
      deform(rng, s, 3e-2);
      s.b1.v = rng.vec3(1.0), s.b1.omega = rng.vec3(3.0);
      s.b2.v = rng.vec3(1.0), s.b2.omega = rng.vec3(3.0);
      Beam elastic = s.beam;
      elastic.damping = 0.0;
      const Wrenches with = evaluate(s.beam, s.b1, s.b2), without = evaluate(elastic, s.b1, s.b2);
      const Vec6 d1 = with.w1 - without.w1, d2 = with.w2 - without.w2;
      const double power = d1.head<3>().dot(s.b1.v) + d1.tail<3>().dot(s.b1.omega) +
                           d2.head<3>().dot(s.b2.v) + d2.tail<3>().dot(s.b2.omega);
      EXPECT_LE(power, 0.0) << name(f) << " case " << i;
    }
  }
}

// The two formulations differ at second order: halving... dividing the deformation by 10 divides
// their relative difference by about 10.
TEST(Beam, FormulationsAgreeToSecondOrder) {
  Random rng(17);
  for (int i = 0; i < 50; ++i) {
    BeamCase s = random_case(rng, Formulation::kEnergy);
    const Vec3 dc = rng.vec3(s.beam.ends.length), th = rng.vec3(1.0);
    double relative[2];
    for (int level = 0; level < 2; ++level) {
      const double size = level == 0 ? 1e-3 : 1e-4;
      const Pose<double> b2 = testing::perturbed(s.b2, size * dc, size * th);
      Beam paper = s.beam;
      paper.formulation = Formulation::kPaper;
      const Wrenches e = evaluate(s.beam, s.b1, b2), p = evaluate(paper, s.b1, b2);
      Eigen::Matrix<double, 12, 1> we, wp;
      we << e.w1, e.w2;
      wp << p.w1, p.w2;
      relative[level] = (we - wp).norm() / we.norm();
    }
    const double ratio = relative[0] / relative[1];
    EXPECT_GT(ratio, 5.0) << "case " << i;
    EXPECT_LT(ratio, 20.0) << "case " << i;
  }
}

}  // namespace
}  // namespace beamrail
