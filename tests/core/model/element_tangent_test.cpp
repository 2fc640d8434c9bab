// The closed-form configuration Jacobian of undamped elements against forward AD through the whole
// kernel (itself checked against central differences in beam_test and rail_test).
#include "core/model/element_tangent.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include "core/model/beam.hpp"
#include "core/model/rail.hpp"
#include "tests/support/random_elements.hpp"

namespace beamrail {
namespace {

using testing::Random;

TEST(ElementTangent, ClosedFormJacobianEqualsAutomaticDifferentiation) {
  const char* kinds[] = {"beam", "prismatic rail", "cylindrical rail"};
  for (Formulation form : {Formulation::kEnergy, Formulation::kPaper})
    for (int kind = 0; kind < 3; ++kind) {
      Random rng(40 + kind);
      double worst = 0;
      for (int i = 0; i < 100; ++i) {
        const Pose<double> b1 = testing::pose(rng.vec3(1.0), rng.rotation());
        Pose<double> b2 = testing::pose(rng.vec3(1.0) + Vec3(2, 0, 0), rng.rotation());
        const ElementEnds ends = testing::make_ends(b1.u + rng.vec3(0.2), b2.u + rng.vec3(0.2),
                                                    b1.u + rng.vec3(1.0), b1, b2);
        // Deformations up to a few hundredths (rotations 0.05 rad): geometric terms matter.
        b2 = testing::perturbed(b2, rng.vec3(2e-2), rng.vec3(5e-2));
        Mat12 ad, closed;
        if (kind == 0) {
          Beam beam;
          beam.ends = ends;
          beam.ea = 2.1e7, beam.gj = 113, beam.eiy = 175, beam.eiz = 230;
          beam.formulation = form;
          const auto kernel = [&](const Pose<Ad12>& p1, const Pose<Ad12>& p2, Vec6T<Ad12>& w1,
                                  Vec6T<Ad12>& w2) { beam_wrenches(beam, p1, p2, w1, w2); };
          ad = element_jacobian(seed_configuration(b1, 0), seed_configuration(b2, 6), kernel);
          closed = configuration_jacobian(element_frames(ends, b1, b2, rotation_measure(beam)),
                                          form, rotation_measure(beam),
                                          [&](const Vec6T<Ad6>& s) { return beam_law(beam, s); });
        } else {
          Rail rail;
          rail.ends = ends;
          rail.type = kind == 1 ? RailType::kPrismatic : RailType::kCylindrical;
          rail.gj = kind == 1 ? 113 : 0, rail.eiy = 175, rail.eiz = 230;
          rail.formulation = form;
          rail.min_length = 1e-3;
          const auto kernel = [&](const Pose<Ad12>& p1, const Pose<Ad12>& p2, Vec6T<Ad12>& w1,
                                  Vec6T<Ad12>& w2) {
            bool floored;
            rail_wrenches(rail, p1, p2, w1, w2, &floored);
          };
          ad = element_jacobian(seed_configuration(b1, 0), seed_configuration(b2, 6), kernel);
          closed = configuration_jacobian(element_frames(ends, b1, b2, rotation_measure(rail)),
                                          form, rotation_measure(rail), [&](const Vec6T<Ad6>& s) {
                                            bool floored;
                                            return rail_law(rail, s, &floored);
                                          });
        }
        worst = std::max(worst, (ad - closed).cwiseAbs().maxCoeff() / ad.cwiseAbs().maxCoeff());
      }
      std::printf("%s, %s: closed form vs AD, worst relative difference %.2e\n", kinds[kind],
                  form == Formulation::kEnergy ? "energy" : "paper", worst);
      EXPECT_LT(worst, 1e-12);
    }
}

// The energy law's rotation vector beyond the small-angle range (relative rotations 0.5 to 2.9
// rad, deformed chords) and exactly at rest (A = I exactly), where the closed form differentiates
// T through the series branches of relative_rotation_vector.
TEST(ElementTangent, ClosedFormJacobianOfTheRotationVectorLawAtLargeRotationsAndAtRest) {
  Random rng(45);
  double worst = 0;
  for (int i = 0; i < 200; ++i) {
    Pose<double> b1 = testing::pose(rng.vec3(1.0), rng.rotation());
    Pose<double> b2 = testing::pose(rng.vec3(1.0) + Vec3(2, 0, 0), rng.rotation());
    if (i == 0) {
      b1 = testing::pose(Vec3::Zero(), Mat3::Identity());
      b2 = testing::pose(Vec3(2, 0, 0), Mat3::Identity());
    }
    const ElementEnds ends =
        i == 0 ? testing::make_ends(Vec3::Zero(), Vec3(2, 0, 0), Vec3(0, 1, 0), b1, b2)
               : testing::make_ends(b1.u + rng.vec3(0.2), b2.u + rng.vec3(0.2),
                                    b1.u + rng.vec3(1.0), b1, b2);
    if (i > 0)
      b2 =
          testing::perturbed(b2, rng.vec3(0.1), rng.uniform(0.5, 2.9) * rng.vec3(1.0).normalized());
    Beam beam;
    beam.ends = ends;
    beam.ea = 2.1e7, beam.gj = 113, beam.eiy = 175, beam.eiz = 230;
    beam.formulation = Formulation::kEnergy;
    const auto kernel = [&](const Pose<Ad12>& p1, const Pose<Ad12>& p2, Vec6T<Ad12>& w1,
                            Vec6T<Ad12>& w2) { beam_wrenches(beam, p1, p2, w1, w2); };
    const Mat12 ad = element_jacobian(seed_configuration(b1, 0), seed_configuration(b2, 6), kernel);
    const ElementFrames<double> f = element_frames(ends, b1, b2, RotationMeasure::kRotationVector);
    if (i == 0) ASSERT_EQ(f.a, Mat3::Identity());
    const Mat12 closed =
        configuration_jacobian(f, Formulation::kEnergy, RotationMeasure::kRotationVector,
                               [&](const Vec6T<Ad6>& s) { return beam_law(beam, s); });
    ASSERT_TRUE(closed.allFinite()) << "case " << i;
    worst = std::max(worst, (ad - closed).cwiseAbs().maxCoeff() / ad.cwiseAbs().maxCoeff());
  }
  std::printf("beam, energy, rotations 0.5-2.9 rad and at rest: closed form vs AD, worst %.2e\n",
              worst);
  EXPECT_LT(worst, 1e-12);
}

}  // namespace
}  // namespace beamrail
