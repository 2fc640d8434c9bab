#include "optimizer/run/designs.hpp"

#include <chrono>
#include <limits>

#include "optimizer/output/tables.hpp"
#include "optimizer/run/evaluation.hpp"

namespace beamrail {

DesignEvaluator::DesignEvaluator(const Study& study) : study_(study), base_(study.document) {
  base_.erase("study");
  for (const DesignVariable& v : study.design->variables) {
    pointers_.emplace_back(v.pointers.begin(), v.pointers.end());
    for (const std::string& p : v.pointers) scene_only_ = scene_only_ && p.rfind("/scene/", 0) == 0;
  }
  bool tracked = false;
  for (const ResponseSpec& r : study.responses) tracked = tracked || r.track;
  if (!tracked) return;
  EvaluationOptions options;
  options.structure_cache = structures_.get();
  const Evaluation ev = beamrail::evaluate(study, study.model, options);
  if (ev.status == Status::kOk)
    references_ = ev.tracked_shapes;
  else
    setup_failure_ =
        "the study's own design, whose mode shapes the tracked frequency responses follow, "
        "did not evaluate: " +
        std::string(status_name(ev.status)) + ": " + ev.message;
}

Json DesignEvaluator::document(const std::vector<double>& x) const {
  Json doc = base_;
  const auto& variables = study_.design->variables;
  for (size_t i = 0; i < pointers_.size(); ++i)
    for (size_t k = 0; k < pointers_[i].size(); ++k)
      doc[pointers_[i][k]] = variables[i].factors[k] * x[i] + variables[i].offsets[k];
  return doc;
}

namespace {

// The problems of an invalid design on one line.
std::string problems(const Diagnostics& diag) {
  std::string out;
  for (const Diagnostic& d : diag.items()) {
    if (!out.empty()) out += "; ";
    out += d.pointer + ": " + d.message;
  }
  return out;
}

}  // namespace

ResponseSensitivities DesignEvaluator::sensitivities(const std::vector<double>& x,
                                                     const Study& design,
                                                     const Evaluation& ev) const {
  const auto& variables = study_.design->variables;
  const int nv = static_cast<int>(variables.size());
  std::vector<double> h(nv);
  for (int j = 0; j < nv; ++j)
    h[j] = sensitivity_step(x[j], variables[j].upper - variables[j].lower);
  // The studies at x +- h_j e_j, built in parallel (one thread inside a parallel batch).
  std::vector<std::optional<Study>> plus(nv), minus(nv);
  std::vector<std::string> invalid(2 * nv);
#pragma omp parallel for schedule(dynamic, 1) if (nv > 1)
  for (int i = 0; i < 2 * nv; ++i) {
    const int j = i / 2;
    std::vector<double> at = x;
    at[j] += (i % 2 == 0 ? 1.0 : -1.0) * h[j];
    Diagnostics diag;
    auto& out = i % 2 == 0 ? plus[j] : minus[j];
    out = build(at, diag);
    if (!out) invalid[i] = problems(diag);
  }
  for (int i = 0; i < 2 * nv; ++i)
    if (!invalid[i].empty()) {
      ResponseSensitivities out;
      out.message = "no derivative with respect to \"" + variables[i / 2].name +
                    "\": the design a step of " + format_number(h[i / 2]) +
                    " away is invalid: " + invalid[i];
      return out;
    }
  std::vector<const Study*> p, m;
  for (int j = 0; j < nv; ++j) p.push_back(&*plus[j]), m.push_back(&*minus[j]);
  return response_sensitivities(design, ev, p, m, h);
}

std::optional<Study> DesignEvaluator::build(const std::vector<double>& x, Diagnostics& diag) const {
  if (scene_only_) {
    std::unique_ptr<Json> doc;
    {
      std::lock_guard<std::mutex> lock(pool_mutex_);
      if (!pool_.empty()) doc = std::move(pool_.back()), pool_.pop_back();
    }
    if (!doc) doc = std::make_unique<Json>(base_);
    // Every variable's numbers are written: what an earlier design wrote is overwritten.
    const auto& variables = study_.design->variables;
    for (size_t i = 0; i < pointers_.size(); ++i)
      for (size_t k = 0; k < pointers_[i].size(); ++k)
        (*doc)[pointers_[i][k]] = variables[i].factors[k] * x[i] + variables[i].offsets[k];
    bool full = false;
    auto s = rebuild_scene(study_, *doc, diag, &full);
    {
      std::lock_guard<std::mutex> lock(pool_mutex_);
      pool_.push_back(std::move(doc));
    }
    if (s || !full) return s;
    diag = Diagnostics();
  }
  return load_study(document(x), study_.file, study_.directory, diag,
                    &study_.model.segment_choices);
}

DesignOutcome DesignEvaluator::evaluate(const std::vector<double>& x,
                                        ResponseSensitivities* sensitivities) const {
  const auto start = std::chrono::steady_clock::now();
  DesignOutcome out;
  out.responses.assign(study_.responses.size(), std::numeric_limits<double>::quiet_NaN());
  try {
    Diagnostics diag;
    const auto design = build(x, diag);
    if (!design) {
      // The first problem names what the values broke (zero-length beam, point on the axis...).
      out.status = Status::kInvalid;
      out.message = problems(diag);
    } else {
      EvaluationOptions options;
      options.max_seconds = study_.design->max_seconds_per_design;
      options.structure_cache = structures_.get();
      if (!references_.empty()) options.mode_references = &references_;
      options.keep_states = sensitivities != nullptr;
      const Evaluation ev = beamrail::evaluate(*design, design->model, options);
      if (sensitivities) {
        if (ev.status == Status::kOk) {
          *sensitivities = this->sensitivities(x, *design, ev);
        } else {
          *sensitivities = ResponseSensitivities();
          sensitivities->message = "the design did not evaluate";
        }
      }
      out.status = ev.status;
      out.message = ev.message;
      out.responses = ev.responses;
      out.warnings = static_cast<int>(ev.warnings.size());
      for (const std::string& w : ev.warnings)
        out.message += (out.message.empty() ? "" : "; ") + std::string("warning: ") + w;
    }
  } catch (const std::exception& e) {
    out.status = Status::kFailed;
    out.message = e.what();
  }
  for (char& c : out.message)  // a table row holds it on one line
    if (c == '\n' || c == '\r') c = ' ';
  out.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace beamrail
