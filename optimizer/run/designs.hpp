// Evaluating designs: the study with its design variables set to given values is rebuilt,
// re-validated and run. Each call builds its own Model and Data, so designs evaluate in parallel;
// designs of one topology share the sparse Jacobian structure and its KLU ordering.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/analysis/sparse_structure.hpp"
#include "optimizer/run/evaluation.hpp"
#include "optimizer/run/responses.hpp"
#include "optimizer/run/sensitivities.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

struct DesignOutcome {
  Status status = Status::kOk;
  // One line: why the design failed (if it did), then "warning: ..." for each warning of its
  // analyses, separated by "; ".
  std::string message;
  std::vector<double> responses;  // one per study.responses (NaN when not computed)
  int warnings = 0;               // how many warnings its analyses gave
  double wall_seconds = 0.0;
};

class DesignEvaluator {
 public:
  // Evaluates the study's own design first when a frequency response tracks its mode by shape:
  // its shapes are the references.
  explicit DesignEvaluator(const Study& study);

  // Why the study's own design, whose mode shapes tracked responses follow, could not be
  // evaluated ("" when it could, or nothing is tracked): the study cannot run.
  const std::string& setup_failure() const { return setup_failure_; }

  // Thread-safe: reads only the evaluator's constant state. With `sensitivities`, also the
  // derivatives of every response with respect to every variable at x (the design's scene built
  // once more per variable on hyper-dual numbers, not analysed: optimizer/run/sensitivities.hpp);
  // they are left !ok with a message when the design did not evaluate or has none.
  DesignOutcome evaluate(const std::vector<double>& x,
                         ResponseSensitivities* sensitivities = nullptr) const;

  // The study document with the variables set to x and no design study: a study that
  // `beamrail run` runs as is.
  Json document(const std::vector<double>& x) const;

  // The study of the design x: its scene rebuilt from the numbers when every variable addresses the
  // scene (rebuild_scene), else the whole document read again. nullopt when x breaks the study
  // (the problems in diag).
  std::optional<Study> build(const std::vector<double>& x, Diagnostics& diag) const;

  const Study& study() const { return study_; }
  // The structures analysed for, and reused by, the evaluations so far.
  const SparseStructureCache& structures() const { return *structures_; }
  size_t n_variables() const { return study_.design->variables.size(); }

 private:
  ResponseSensitivities sensitivities(const std::vector<double>& x, const Study& design,
                                      const Evaluation& ev) const;

  const Study& study_;
  Json base_;                                              // study.document without "study"
  std::vector<std::vector<Json::json_pointer>> pointers_;  // per variable
  std::shared_ptr<SparseStructureCache> structures_ = std::make_shared<SparseStructureCache>();
  ModeShapes references_;   // of tracked frequency responses
  bool scene_only_ = true;  // every variable addresses a number of the scene
  // Copies of the study document that designs' values are written into (one per evaluation under
  // way, reused: no document is copied per design).
  mutable std::mutex pool_mutex_;
  mutable std::vector<std::unique_ptr<Json>> pool_;
  std::string setup_failure_;
};

}  // namespace beamrail
