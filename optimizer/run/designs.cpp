#include "optimizer/run/designs.hpp"

#include <chrono>
#include <limits>
#include <map>
#include <optional>

#include "core/scene/scene_loader.hpp"
#include "optimizer/run/evaluation.hpp"
#include "optimizer/run/number_text.hpp"

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
  ResponseSensitivities out;
  // The derivatives follow the scene's numbers: a variable elsewhere (an analysis's option, a
  // response's direction) changes what the analyses compute, not the model.
  for (int j = 0; j < nv; ++j)
    for (const std::string& p : variables[j].pointers)
      if (p.rfind("/scene/", 0) != 0) {
        out.message =
            "no exact derivative with respect to \"" + variables[j].name + "\": " + p +
            " is not a number of the inline scene (an optimization can take \"gradient\": \"fd\")";
        return out;
      }
  // The design's model along each variable: its scene built on hyper-dual numbers, the
  // variable's numbers seeded with their factors.
  std::vector<std::optional<DualModel>> directions(nv);
  std::vector<std::string> refused(nv);
  const Json doc = document(x);
  const Where scene = Where{study_.file, ""} / "scene";
#pragma omp parallel for schedule(dynamic, 1) if (nv > 1)
  for (int j = 0; j < nv; ++j) {
    std::map<std::string, double> seeds;
    for (size_t k = 0; k < pointers_[j].size(); ++k)
      seeds[pointers_[j][k].to_string()] += variables[j].factors[k];
    Diagnostics diag;
    try {  // nothing may leave the parallel region
      directions[j] =
          load_dual_scene(doc.at("scene"), scene, seeds, design.model.segment_choices, diag);
      if (!directions[j]) refused[j] = problems(diag);
    } catch (const std::exception& e) {
      refused[j] = std::string("the scene's build on dual numbers failed: ") + e.what();
    } catch (...) {
      refused[j] =
          "the scene's build on dual numbers threw an exception that is not a "
          "std::exception";
    }
  }
  std::vector<DualModel> along;
  for (int j = 0; j < nv; ++j) {
    if (!directions[j]) {
      out.message = "no exact derivative with respect to \"" + variables[j].name +
                    "\": " + refused[j] + " (an optimization can take \"gradient\": \"fd\")";
      return out;
    }
    along.push_back(std::move(*directions[j]));
  }
  return response_sensitivities(design, ev, along);
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
  } catch (...) {  // muparser's errors, say, are no std::exception
    out.status = Status::kFailed;
    out.message = kUnknownException;
  }
  for (char& c : out.message)  // a table row holds it on one line
    if (c == '\n' || c == '\r') c = ' ';
  out.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace beamrail
