// Designs of one topology share the sparse Jacobian structure and its KLU ordering: a sweep over
// section sizes and lengths of a segmented cantilever analyses the topology once, on one thread
// or several, and every design's responses equal those of the design evaluated on its own. The
// static analysis's tangent (KLU on the same velocity-level pattern) shares it too, and modal
// analyses share the fill-reducing ordering of their shift-invert factorization.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "core/scene/json_reader.hpp"
#include "optimizer/run/designs.hpp"
#include "optimizer/run/evaluation.hpp"

namespace beamrail {
namespace {

// A 6-segment steel cantilever (78 states: the sparse solver) hit by a step load; peak tip
// deflection over 20 ms. Variables: the section width and the beam length.
const char* kStudy = R"({"name": "reuse", "scene": {
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq",
               "segments": 6}],
    "loads": [{"type": "force", "body": "tip", "value": [0, -1, 0],
               "time": {"type": "step", "at": 0.0}}]},
  "analyses": [{"type": "transient", "t_end": 0.02, "output_step": 0.001,
                "integrator": {"method": "dirk", "rtol": 1e-6, "atol": 1e-9,
                               "linear_solver": "sparse"}}],
  "responses": {"peak": {"quantity": "peak_displacement", "body": "tip", "direction": [0, -1, 0]}},
  "study": {"type": "sweep", "sampling": "grid", "variables": [
    {"name": "width", "pointer": "/scene/sections/sq/width", "lower": 0.008, "upper": 0.012,
     "count": 3},
    {"name": "length", "pointer": ["/scene/bodies/0/position/0", "/scene/beams/0/point2/0"],
     "lower": 0.9, "upper": 1.1, "count": 3}]}})";

std::optional<Study> load(Diagnostics& diag, const std::string& text = kStudy) {
  const auto document = parse_json(text, "reuse.json", diag);
  if (!document) return std::nullopt;
  return load_study(*document, "reuse.json", ".", diag);
}

// The design evaluated alone: its own model, no shared structure.
double alone(const DesignEvaluator& evaluator, const std::vector<double>& x) {
  Diagnostics diag;
  const auto design = load_study(evaluator.document(x), "reuse.json", ".", diag);
  EXPECT_TRUE(design) << diag.format();
  if (!design) return NAN;
  const Evaluation ev = evaluate(*design, design->model, {});
  EXPECT_EQ(ev.status, Status::kOk) << ev.message;
  return ev.responses.at(0);
}

TEST(DesignReuse, DesignsOfOneTopologyShareOneAnalysedStructure) {
  Diagnostics diag;
  const auto study = load(diag);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  std::vector<std::vector<double>> designs;
  for (double w : {0.008, 0.01, 0.012})
    for (double l : {0.9, 1.0, 1.1}) designs.push_back({w, l});

  // One thread: the first design analyses the topology, the others reuse it.
  std::vector<double> peaks;
  for (const auto& x : designs) {
    const DesignOutcome o = evaluator.evaluate(x);
    ASSERT_EQ(o.status, Status::kOk) << o.message;
    peaks.push_back(o.responses.at(0));
  }
  EXPECT_EQ(evaluator.structures().analyses(), 1);
  EXPECT_EQ(evaluator.structures().reuses(), static_cast<long>(designs.size()) - 1);

  // Responses differ between designs (the structure is shared, not the values) and equal each
  // design's run on its own, bit for bit.
  // (thick and long vs thin and short: statically (1.1 / 0.9)^3 / 1.5^4 = 0.36; within 20 ms the
  // peaks differ less.)
  EXPECT_LT(peaks.back() / peaks.front(), 0.8);
  for (size_t k = 1; k < designs.size(); ++k) EXPECT_NE(peaks[k], peaks[k - 1]);
  for (size_t k = 0; k < designs.size(); ++k) EXPECT_EQ(peaks[k], alone(evaluator, designs[k]));

  // Two threads evaluating at once share it too, and give the same responses.
  std::vector<double> parallel(designs.size());
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t)
    threads.emplace_back([&, t] {
      for (size_t k = static_cast<size_t>(t); k < designs.size(); k += 2)
        parallel[k] = evaluator.evaluate(designs[k]).responses.at(0);
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(evaluator.structures().analyses(), 1);
  EXPECT_EQ(evaluator.structures().reuses(), 2 * static_cast<long>(designs.size()) - 1);
  for (size_t k = 0; k < designs.size(); ++k) EXPECT_EQ(parallel[k], peaks[k]);
}

// The same sweep with a static analysis (and a modal analysis about it): Newton's tangents are
// factored with the shared analysis; deflections equal the lone runs bit for bit and follow the
// closed form P l^3 / (3 E I) of each design.
TEST(DesignReuse, StaticAnalysesShareTheStructureToo) {
  std::string text = kStudy;
  const std::string transient = text.substr(text.find(R"({"type": "transient")"));
  text.replace(text.find(R"({"type": "transient")"), transient.find("}}],") + 2,
               R"({"type": "static"}, {"type": "modal", "modes": 2, "about": "static"})");
  const std::string peak = R"({"quantity": "peak_displacement")";
  text.replace(text.find(peak), peak.size(), R"({"quantity": "displacement")");
  Diagnostics diag;
  const auto study = load(diag, text);
  ASSERT_TRUE(study) << diag.format() << text;
  const DesignEvaluator evaluator(*study);
  for (double w : {0.008, 0.012})
    for (double l : {0.9, 1.1}) {
      const DesignOutcome o = evaluator.evaluate({w, l});
      ASSERT_EQ(o.status, Status::kOk) << o.message;
      // Bending in x-y: I = height width^3 / 12, the sweep varies the width only.
      const double closed = l * l * l / (3.0 * 2.1e11 * 0.01 * w * w * w / 12.0);
      const double deflection = o.responses.at(0);
      // The chain of 6 beams carries the tip load as one beam would, less the geometric
      // nonlinearity: the tip deflection falls short of the linear one by (deflection / l)^2
      // (measured to 0.5 %; 2e-6 .. 2e-5 here).
      const double second_order = (closed / l) * (closed / l);
      EXPECT_NEAR(1.0 - deflection / closed, second_order, 0.1 * second_order) << w << " " << l;
      Diagnostics d;
      const auto design = load_study(evaluator.document({w, l}), "reuse.json", ".", d);
      ASSERT_TRUE(design) << d.format();
      const Evaluation ev = evaluate(*design, design->model, {});
      EXPECT_EQ(ev.responses.at(0), deflection);
    }
  EXPECT_EQ(evaluator.structures().analyses(), 1);
  EXPECT_EQ(evaluator.structures().reuses(), 3);
}

// A sweep of modal analyses (about the initial state: no static analysis) shares one ordering of
// K + mu M for its shift-invert factorizations and makes no Jacobian structure; each design's
// frequencies equal its lone run's bit for bit, on one thread or two.
TEST(DesignReuse, ModalAnalysesShareTheOrdering) {
  std::string text = kStudy;
  const std::string transient = text.substr(text.find(R"({"type": "transient")"));
  text.replace(text.find(R"({"type": "transient")"), transient.find("}}],") + 2,
               R"({"type": "modal", "modes": 3, "about": "initial"})");
  const std::string peak =
      R"({"quantity": "peak_displacement", "body": "tip", "direction": [0, -1, 0]})";
  text.replace(text.find(peak), peak.size(), R"({"quantity": "frequency", "mode": 3})");
  const std::string six = R"("segments": 6)";
  text.replace(text.find(six), six.size(), R"("segments": 12)");  // 72 dofs: shift-invert
  Diagnostics diag;
  const auto study = load(diag, text);
  ASSERT_TRUE(study) << diag.format() << text;
  const DesignEvaluator evaluator(*study);
  std::vector<std::vector<double>> designs;
  for (double w : {0.008, 0.012})
    for (double l : {0.9, 1.1}) designs.push_back({w, l});
  std::vector<double> f3;
  for (const auto& x : designs) {
    const DesignOutcome o = evaluator.evaluate(x);
    ASSERT_EQ(o.status, Status::kOk) << o.message;
    f3.push_back(o.responses.at(0));
    EXPECT_EQ(o.responses.at(0), alone(evaluator, x));
  }
  for (size_t k = 1; k < designs.size(); ++k) EXPECT_NE(f3[k], f3[k - 1]);
  EXPECT_EQ(evaluator.structures().orderings(), 1);
  EXPECT_EQ(evaluator.structures().ordering_reuses(), static_cast<long>(designs.size()) - 1);
  EXPECT_EQ(evaluator.structures().analyses(), 0);
  std::vector<double> parallel(designs.size());
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t)
    threads.emplace_back([&, t] {
      for (size_t k = static_cast<size_t>(t); k < designs.size(); k += 2)
        parallel[k] = evaluator.evaluate(designs[k]).responses.at(0);
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(evaluator.structures().orderings(), 1);
  for (size_t k = 0; k < designs.size(); ++k) EXPECT_EQ(parallel[k], f3[k]);
}

// A design whose values change what the study reads from the scene beyond its numbers (gravity
// switched off turns the modal analysis's default linearization from the static equilibrium to
// the initial state) is read whole, not rebuilt from its scene: its responses equal its lone run's.
TEST(DesignReuse, ValuesThatChangeTheAnalysesDefaultsReadTheWholeStudy) {
  const std::string text = R"({"name": "gravity", "scene": {
    "gravity": [0, 0, -9.81],
    "materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "tip", "mass": 5, "inertia": [1e-3, 1e-3, 1e-3], "position": [1, 0, 0]}],
    "beams": [{"name": "arm", "body1": "ground", "body2": "tip", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq",
               "segments": 3}]},
  "analyses": [{"type": "modal", "modes": 2}],
  "responses": {"f1": {"quantity": "frequency", "mode": 1}},
  "study": {"type": "sweep", "sampling": "list", "rows": [[-9.81], [0], [-30]], "variables": [
    {"name": "g", "pointer": "/scene/gravity/2"}]}})";
  Diagnostics diag;
  const auto study = load(diag, text);
  ASSERT_TRUE(study) << diag.format();
  const DesignEvaluator evaluator(*study);
  std::vector<double> f;
  for (double g : {-9.81, 0.0, -30.0}) {
    const DesignOutcome o = evaluator.evaluate({g});
    ASSERT_EQ(o.status, Status::kOk) << o.message;
    EXPECT_EQ(o.responses.at(0), alone(evaluator, {g})) << g;
    f.push_back(o.responses.at(0));
  }
  // Linearized about the sagged equilibrium, f1 moves with gravity (about the initial state
  // without it): the three designs differ.
  EXPECT_NE(f[1], f[0]);
  EXPECT_NE(f[0], f[2]);
}

// "segments": "auto" chooses once, for the study's scene, and every design keeps that count (its
// responses stay continuous in the variables). With a band of 130 Hz the 1 m cantilever checks
// its first two bending frequencies (8.4 and 52 Hz; the third is 147 Hz); at 1.1 m the third
// (121 Hz) enters the band, so that design read on its own chooses more segments (28 instead of
// 24 at 1e-2) -- the design the evaluator builds keeps the study's.
TEST(DesignReuse, AutoSegmentCountsAreTheStudysForEveryDesign) {
  std::string text = kStudy;
  const std::string fixed = "\"segments\": 6";
  text.replace(text.find(fixed), fixed.size(), "\"segments\": \"auto\"");
  text.replace(text.find("\"beams\""), 0,
               "\"segmentation\": {\"frequency_error\": 1e-2, \"max_frequency_hz\": 130}, ");
  Diagnostics diag;
  const auto study = load(diag, text);
  ASSERT_TRUE(study) << diag.format();
  ASSERT_EQ(study->model.segment_choices.size(), 1u);
  const SegmentChoice& own = study->model.segment_choices[0];
  EXPECT_EQ(own.frequencies_checked, 2);
  EXPECT_FALSE(own.pinned);
  const DesignEvaluator evaluator(*study);
  const std::vector<double> longer{0.01, 1.1};
  const auto design = evaluator.build(longer, diag);
  ASSERT_TRUE(design) << diag.format();
  ASSERT_EQ(design->model.segment_choices.size(), 1u);
  EXPECT_EQ(design->model.segment_choices[0].segments, own.segments);
  EXPECT_TRUE(design->model.segment_choices[0].pinned);
  EXPECT_EQ(static_cast<long>(design->model.beams.size()), own.segments);

  const auto alone = load_study(evaluator.document(longer), "reuse.json", ".", diag);
  ASSERT_TRUE(alone) << diag.format();
  EXPECT_EQ(alone->model.segment_choices[0].frequencies_checked, 3);
  EXPECT_GT(alone->model.segment_choices[0].segments, own.segments);
  EXPECT_FALSE(alone->model.segment_choices[0].pinned);

  // The design's document with the counts written in (what best_scene.json holds) reads as the
  // design the evaluator built: the study's count, no "auto" left and no segmentation target.
  Json document = evaluator.document(longer);
  EXPECT_EQ(write_segment_counts(document, study->model.segment_choices),
            "arm " + std::to_string(own.segments));
  EXPECT_EQ(document["scene"]["beams"][0]["segments"], own.segments);
  EXPECT_FALSE(document["scene"].contains("segmentation"));
  const auto written = load_study(document, "reuse.json", ".", diag);
  ASSERT_TRUE(written) << diag.format();
  EXPECT_TRUE(written->model.segment_choices.empty());
  EXPECT_EQ(written->model.beams.size(), design->model.beams.size());
  EXPECT_TRUE(written->input_warnings.empty());
}

}  // namespace
}  // namespace beamrail
