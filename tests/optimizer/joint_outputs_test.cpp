// Joints in the outputs of a static analysis (docs/study_files.md): element_forces.csv rows in the
// joint frame, joint_gaps.csv, and the responses element_force (of a joint) and joint_gap; read
// back from the tables and the responses and compared with the statics of a weight on a joint:
//  - a weight W = m g hanging from a spherical joint: the joint force is W, its gap W / k_f;
//  - a weight on a bracket: a body whose centre lies d beside a fixed joint: the joint carries W
//    and the moment W d, and gives way by the gap W / k_f and the angle W d / k_m.
// Without beams or rails the joints' stiffness is k_f = W / (d c), k_m = W d / c (docs/model.md
// "Joints"), so the gap is c d and the bracket's angle c, with c the relative compliance.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "optimizer/run/evaluation.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {
namespace {

constexpr double kMass = 3.0, kG = 9.81, kD = 0.5, kCompliance = 1e-6;

// A body of kMass whose centre lies at `centre` from a joint of `type` at the origin to ground,
// under gravity -y; responses of the joint's end forces and gap.
Json study(const std::string& type, const Json& centre) {
  return {
      {"name", "joint_outputs"},
      {"scene",
       {{"gravity", {0, -kG, 0}},
        {"bodies",
         {{{"name", "weight"},
           {"mass", kMass},
           {"inertia", {0.01, 0.02, 0.03}},
           {"position", centre}}}},
        {"joints",
         {{{"name", "j"},
           {"type", type},
           {"body1", "ground"},
           {"body2", "weight"},
           {"point", {0, 0, 0}},
           {"relative_compliance", kCompliance}}}}}},
      {"analyses", {{{"type", "static"}}}},
      {"responses",
       {{"fy2", {{"quantity", "element_force"}, {"element", "j"}, {"end", 2}, {"component", "fy"}}},
        {"fy1", {{"quantity", "element_force"}, {"element", "j"}, {"component", "fy"}}},
        {"mz2", {{"quantity", "element_force"}, {"element", "j"}, {"end", 2}, {"component", "mz"}}},
        {"gap", {{"quantity", "joint_gap"}, {"joint", "j"}}}}}};
}

struct Outcome {
  std::map<std::string, double> responses;
  std::map<std::string, std::map<std::string, std::string>> forces;  // "j.1", "j.2" -> column
  std::map<std::string, std::string> gaps;                           // joint_gaps.csv's row
};

Outcome run(const Json& doc) {
  Diagnostics diag;
  const auto s = load_study(doc, "joint_outputs.json", ".", diag);
  EXPECT_TRUE(s) << diag.format();
  Outcome out;
  if (!s) return out;
  // The frame of the joint is the global one (ground's axes; no axis given).
  EXPECT_LT((s->model.joints[0].frame1 - Mat3::Identity()).norm(), 1e-15);
  EvaluationOptions options;
  options.result_tables = true;
  const Evaluation ev = evaluate(*s, s->model, options);
  EXPECT_EQ(ev.status, Status::kOk) << ev.message;
  for (size_t k = 0; k < s->responses.size(); ++k)
    out.responses[s->responses[k].name] = ev.responses[k];
  for (const ResultTable& t : ev.analyses.at(0).result_tables) {
    const auto row_map = [&](const std::vector<std::string>& row) {
      std::map<std::string, std::string> m;
      for (size_t c = 0; c < t.header.size(); ++c) m[t.header[c]] = row[c];
      return m;
    };
    if (t.file == "element_forces.csv")
      for (const auto& row : t.rows) out.forces[row[0] + "." + row[1]] = row_map(row);
    if (t.file == "joint_gaps.csv") {
      EXPECT_EQ(t.rows.size(), 1u);
      out.gaps = row_map(t.rows.at(0));
    }
  }
  return out;
}

double number(const std::map<std::string, std::string>& row, const std::string& column) {
  return std::stod(row.at(column));
}

TEST(JointOutputs, AWeightHangingFromASphericalJointPullsItWithItsWeight) {
  const Outcome o = run(study("spherical", {0, -kD, 0}));
  const double w = kMass * kG;
  ASSERT_EQ(o.forces.count("j.1") + o.forces.count("j.2"), 2u);
  ASSERT_FALSE(o.gaps.empty());
  std::printf(
      "spherical joint under a %.4f N weight: fy at end 2 %.10f N (table %s), end 1 %.10f "
      "N; gap %.6e m (c d = %.6e), angle %s\n",
      w, o.responses.at("fy2"), o.forces.at("j.2").at("fy").c_str(), o.responses.at("fy1"),
      o.responses.at("gap"), kCompliance * kD, o.gaps.at("angle").c_str());
  // On the joint: pulled down by the weight at end 2 (minus the force it holds the weight up
  // with), held up at end 1. The joint's force is linear in its gap: exact but for rounding.
  EXPECT_NEAR(o.responses.at("fy2"), -w, 1e-9 * w);
  EXPECT_NEAR(o.responses.at("fy1"), w, 1e-9 * w);
  EXPECT_EQ(number(o.forces.at("j.2"), "fy"), o.responses.at("fy2"));
  for (const char* c : {"fx", "fz", "mx", "my", "mz"})
    for (const char* end : {"j.1", "j.2"})
      EXPECT_LT(std::abs(number(o.forces.at(end), c)), 1e-9 * w);
  EXPECT_NEAR(o.responses.at("gap") / (kCompliance * kD), 1.0, 1e-6);
  EXPECT_NEAR(number(o.gaps, "gap"), o.responses.at("gap"), 1e-15);
  EXPECT_NEAR(number(o.gaps, "gy"), -kCompliance * kD,
              1e-6 * kCompliance * kD);  // it stretched down
  EXPECT_EQ(number(o.gaps, "angle"), 0.0);
}

TEST(JointOutputs, AWeightOnABracketHeldByAFixedJointLoadsItWithWAndWd) {
  const Outcome o = run(study("fixed", {kD, 0, 0}));
  const double w = kMass * kG;
  ASSERT_FALSE(o.gaps.empty());
  std::printf(
      "fixed joint, weight %.4f N at %.2f m: fy2 %.10f N, mz2 %.10f N m (W d = %.10f), "
      "gap %.6e m (c d = %.1e), angle %.6e rad (c = %.0e)\n",
      w, kD, o.responses.at("fy2"), o.responses.at("mz2"), w * kD, o.responses.at("gap"),
      kCompliance * kD, number(o.gaps, "angle"), kCompliance);
  EXPECT_NEAR(o.responses.at("fy2"), -w, 1e-9 * w);
  // The bracket turns by c: the weight's lever shortens by d c^2 / 2, far below these bounds.
  EXPECT_NEAR(o.responses.at("mz2"), -w * kD, 1e-9 * w * kD);
  // End 1 holds the same moment about its own point, which lies the gap (c d, along -y) from
  // end 2's: the force along y has no lever along y, so the moments agree to rounding too.
  EXPECT_NEAR(number(o.forces.at("j.1"), "mz"), w * kD, 1e-9 * w * kD);
  EXPECT_NEAR(o.responses.at("gap") / (kCompliance * kD), 1.0, 1e-5);
  EXPECT_NEAR(number(o.gaps, "angle") / kCompliance, 1.0, 1e-5);
}

TEST(JointOutputs, AJointGapOfAnUnknownJointIsRefusedWithItsPointer) {
  Json doc = study("spherical", {0, -kD, 0});
  doc["responses"]["gap"]["joint"] = "nope";
  Diagnostics diag;
  EXPECT_FALSE(load_study(doc, "joint_outputs.json", ".", diag));
  const std::string text = diag.format();
  EXPECT_NE(text.find("joint_outputs.json:/responses/gap/joint: unknown joint \"nope\""),
            std::string::npos)
      << text;
}

}  // namespace
}  // namespace beamrail
