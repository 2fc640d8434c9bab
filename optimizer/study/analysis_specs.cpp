// Reading the "analyses" entries of a study: transient, static, modal and buckling.
#include <cctype>
#include <cmath>

#include "optimizer/study/study.hpp"

namespace beamrail {

const std::vector<std::string> kAnalysisTypes = {"transient", "static", "modal", "buckling"};

namespace {

bool read_transient(ObjectReader& r, AnalysisSpec& a);

}  // namespace

void read_integrator(const Json& value, const Where& where, Diagnostics& diag,
                     IntegratorOptions& io) {
  ObjectReader r(value, where, diag);
  if (!r.is_object()) return;
  if (const auto m = r.choice("method", false, {"auto", "bdf", "adams", "dirk", "erk", "modal"}))
    io.method = *method_from_name(*m);
  if (const auto t = r.string("table", false)) {
    if (io.method != IntegratorMethod::kDirk && io.method != IntegratorMethod::kErk)
      r.error("table", "a Butcher table applies to the \"dirk\" and \"erk\" methods");
    else
      io.table = *t;
  }
  io.rtol = r.positive("rtol", false).value_or(io.rtol);
  io.atol = r.positive("atol", false).value_or(io.atol);
  if (const auto j = r.choice("jacobian", false, {"exact", "fd"}))
    io.jacobian = *j == "exact" ? JacobianKind::kExact : JacobianKind::kFiniteDifference;
  if (const auto s = r.choice("linear_solver", false, {"auto", "dense", "sparse"}))
    io.linear_solver = *s == "dense"    ? LinearSolverKind::kDense
                       : *s == "sparse" ? LinearSolverKind::kSparse
                                        : LinearSolverKind::kAuto;
  if (io.jacobian == JacobianKind::kFiniteDifference &&
      io.linear_solver == LinearSolverKind::kSparse)
    r.error("jacobian", "finite-difference Jacobians need the dense linear solver");
  if (const auto q = r.integer("max_order", false, 1)) {
    const int limit = io.method == IntegratorMethod::kAdams ? 12 : 5;
    if (io.method != IntegratorMethod::kBdf && io.method != IntegratorMethod::kAdams)
      r.error("max_order", "applies to the \"bdf\" and \"adams\" methods");
    else if (*q > limit)
      r.error("max_order", std::string(method_name(io.method)) + " orders go from 1 to " +
                               std::to_string(limit));
    else
      io.max_order = static_cast<int>(*q);
  }
  if (const auto d = r.boolean("stability_limit_detection", false)) {
    if (io.method != IntegratorMethod::kBdf)
      r.error("stability_limit_detection", "applies to the \"bdf\" method");
    io.stability_limit_detection = *d;
  }
  io.max_step = r.positive("max_step", false).value_or(0.0);
  io.initial_step = r.positive("initial_step", false).value_or(0.0);
  if (const auto h = r.positive("fixed_step", false)) {
    if (io.method != IntegratorMethod::kDirk && io.method != IntegratorMethod::kErk)
      r.error("fixed_step", "applies to the \"dirk\" and \"erk\" methods");
    else if (io.max_step > 0.0 || io.initial_step > 0.0)
      r.error("fixed_step", "sets every step: max_step and initial_step do not apply with it");
    else
      io.fixed_step = *h;
  }
  io.max_steps = r.integer("max_steps", false, 1).value_or(io.max_steps);
  if (const Json* band = r.member("max_frequency_hz", false)) {
    const bool chosen = band->is_string() && band->get<std::string>() == "auto";
    const auto f =
        band->is_string() ? std::optional<double>() : r.positive("max_frequency_hz", false);
    if (band->is_string() && !chosen) {
      r.error("max_frequency_hz", "expected a frequency [Hz] > 0 or \"auto\"");
    } else if (chosen || f) {
      if (io.method != IntegratorMethod::kModal && io.method != IntegratorMethod::kAuto)
        r.error("max_frequency_hz", "applies to the \"modal\" and \"auto\" methods");
      else if (chosen)
        io.choose_band = true;
      else
        io.max_frequency_hz = *f;
    }
  }
  if (const auto about = r.choice("about", false, {"static", "initial"})) {
    if (io.method != IntegratorMethod::kModal && io.method != IntegratorMethod::kAuto)
      r.error("about", "applies to the \"modal\" and \"auto\" methods");
    else
      io.about = *about;
  }
}

namespace {

bool read_transient(ObjectReader& r, AnalysisSpec& a) {
  const size_t problems_before = r.diagnostics().items().size();
  const auto t_end = r.positive("t_end", true);
  const auto step = r.positive("output_step", false);
  a.transient.integrator.method =
      IntegratorMethod::kAuto;  // the study file's default (docs/study_files.md)
  if (const Json* i = r.member("integrator", false))
    read_integrator(*i, r.at("integrator"), r.diagnostics(), a.transient.integrator);
  if (const Json* v = r.member("verify", false)) {
    if (v->is_boolean())
      a.verify = v->get<bool>() ? AnalysisSpec::Verify::kAlways : AnalysisSpec::Verify::kNever;
    else if (!(v->is_string() && v->get<std::string>() == "auto"))
      r.error("verify", "expected true, false or \"auto\"");
  }
  if (const auto refine = r.boolean("refine", false)) a.refine = *refine;
  // The band integrated: a frequency [Hz], "output": half the output rate (what the samples
  // can show), or "auto": chosen for rtol. The integrator's own max_frequency_hz, when given,
  // wins.
  double band = -1.0;  // none; 0: "output"; -2: "auto"
  if (const Json* f = r.member("max_frequency_hz", false)) {
    if (f->is_string()) {
      if (f->get<std::string>() == "output")
        band = 0.0;  // from output_step below
      else if (f->get<std::string>() == "auto")
        band = -2.0;
      else
        r.error("max_frequency_hz", "expected a frequency [Hz] > 0, \"output\" or \"auto\"");
    } else {
      band = r.positive("max_frequency_hz", false).value_or(-1.0);
    }
    const IntegratorOptions& io = a.transient.integrator;
    if ((band >= 0.0 || band == -2.0) && io.method != IntegratorMethod::kModal &&
        io.method != IntegratorMethod::kAuto) {
      r.error("max_frequency_hz", "applies to the \"modal\" and \"auto\" methods");
      band = -1.0;
    }
  }
  a.transient.max_seconds = r.positive("max_seconds", false).value_or(0.0);
  if (const auto initial = r.choice("initial", false, {"scene", "static"}))
    a.initial_static = *initial == "static";
  if (!t_end) return false;
  a.transient.t_end = *t_end;
  a.transient.output_step = step.value_or(*t_end / 100.0);
  IntegratorOptions& io = a.transient.integrator;
  if (band == -2.0 && !(io.max_frequency_hz > 0.0)) io.choose_band = true;
  if (band >= 0.0 && !(io.max_frequency_hz > 0.0) && !io.choose_band)
    a.transient.integrator.max_frequency_hz = band > 0.0 ? band : 0.5 / a.transient.output_step;
  if (a.transient.output_step > *t_end) {
    r.error("output_step", "must not exceed t_end");
    return false;
  }
  if (*t_end / a.transient.output_step > 1e8) {
    r.error("output_step", "more than 1e8 output rows requested");
    return false;
  }
  // What the analysis itself refuses, when the checks above, which name the key at fault, found
  // nothing.
  std::string problem;
  if (r.diagnostics().items().size() == problems_before && !a.transient.IsValid(&problem)) {
    r.error("integrator", problem);
    return false;
  }
  return true;
}

bool has_harmonic_load(const Model* model) {
  if (!model) return false;
  for (const Load& load : model->loads)
    if (load.time.type == TimeFunction::Type::kHarmonic) return true;
  return false;
}

// The loads' time of a static or buckling analysis: "time", required when a load is harmonic.
bool read_load_time(ObjectReader& r, const Model* model, double& time) {
  if (const auto t = r.positive("time", false, true)) {
    time = *t;
  } else if (has_harmonic_load(model) && !r.member("time", false)) {
    r.error("type", "the scene has harmonic loads, which have no final value: give \"time\"");
    return false;
  }
  return true;
}

bool read_static(ObjectReader& r, const Model* model, AnalysisSpec& a) {
  bool ok = read_load_time(r, model, a.statics.time);
  a.statics.max_seconds = r.positive("max_seconds", false).value_or(0.0);
  if (const Json* steps = r.member("load_steps", false)) {
    if (steps->is_string()) {
      if (steps->get<std::string>() != "auto") {
        r.error("load_steps", "expected \"auto\" or a number of equal load steps");
        ok = false;
      }
    } else if (const auto n = r.integer("load_steps", false, 1)) {
      if (*n > 100000) {
        r.error("load_steps", "at most 100000 load steps");
        ok = false;
      } else {
        a.statics.load_steps = static_cast<int>(*n);
      }
    } else {
      ok = false;
    }
  }
  a.statics.tolerance = r.positive("tolerance", false).value_or(a.statics.tolerance);
  if (const auto n = r.integer("max_iterations", false, 1))
    a.statics.max_iterations = static_cast<int>(std::min(*n, 10000L));
  // How the loads are raised (docs/study_files.md, the `static` analysis): load steps, or along the
  // path by arc length (through limit points; the path in static_path.csv).
  if (const auto control = r.choice("control", false, {"load", "arc_length"}))
    a.statics.control = *control == "arc_length" ? StaticControl::kArcLength : StaticControl::kLoad;
  else if (r.member("control", false))
    ok = false;
  const bool arc = a.statics.control == StaticControl::kArcLength;
  if (r.member("arc_length", false)) {
    if (!arc) {
      r.error("arc_length", "applies to \"control\": \"arc_length\"");
      ok = false;
    } else if (const auto ds = r.positive("arc_length", false)) {
      a.statics.arc_length = *ds;
    } else {
      ok = false;
    }
  }
  if (arc && r.member("load_steps", false)) {
    r.error("load_steps",
            "applies to \"control\": \"load\" (arc-length control chooses its own steps; "
            "\"arc_length\" bounds their length)");
    ok = false;
  }
  if (const auto n = r.integer("max_steps", false, 1)) {
    if (*n > 1000000) {
      r.error("max_steps", "at most 1000000 steps");
      ok = false;
    } else {
      a.statics.max_load_steps = static_cast<int>(*n);
    }
  }
  return ok;
}

bool read_modal(ObjectReader& r, const Model* model, AnalysisSpec& a) {
  if (const auto n = r.integer("modes", false, 1)) {
    if (*n > 10000) {
      r.error("modes", "at most 10000 modes");
      return false;
    }
    a.modal.modes = static_cast<int>(*n);
  }
  bool loaded = model && model->gravity.norm() > 0.0;
  if (model)
    for (const Load& load : model->loads) loaded = loaded || applies_in_case(load, a.load_case);
  const auto about = r.choice("about", false, {"static", "initial"});
  a.about_static = about ? *about == "static" : loaded;
  if (!a.about_static) a.modal.load_factor = 0.0;
  if (const auto s = r.choice("solver", false, {"auto", "dense", "shift-invert"}))
    a.modal.solver = *s == "dense"          ? EigenSolverKind::kDense
                     : *s == "shift-invert" ? EigenSolverKind::kShiftInvert
                                            : EigenSolverKind::kAuto;
  a.modal.max_seconds = r.positive("max_seconds", false).value_or(0.0);
  return true;
}

bool read_buckling(ObjectReader& r, const Model* model, AnalysisSpec& a) {
  bool ok = read_load_time(r, model, a.buckling.time);
  if (const auto n = r.integer("modes", false, 1)) {
    if (*n > 10000) {
      r.error("modes", "at most 10000 modes");
      ok = false;
    } else {
      a.buckling.modes = static_cast<int>(*n);
    }
  }
  if (const auto s = r.choice("solver", false, {"auto", "dense", "lanczos"}))
    a.buckling.solver = *s == "dense"     ? EigenSolverKind::kDense
                        : *s == "lanczos" ? EigenSolverKind::kShiftInvert
                                          : EigenSolverKind::kAuto;
  a.buckling.max_seconds = r.positive("max_seconds", false).value_or(0.0);
  return ok;
}

// An analysis name: it names tables (<name>.<table>), so it must be a plain file-name part.
bool valid_analysis_name(const std::string& name) {
  if (name.empty() || name.size() > 64 || name[0] == '.') return false;
  for (char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.')
      return false;
  return true;
}

}  // namespace

std::optional<AnalysisSpec> read_analysis(const Json& value, const Where& where, const Model* model,
                                          Diagnostics& diag) {
  ObjectReader r(value, where, diag);
  if (!r.is_object()) return std::nullopt;
  AnalysisSpec a;
  a.where = where;
  const auto type = r.choice("type", true, kAnalysisTypes);
  const auto name = r.string("name", false);
  const auto load_case = r.string("load_case", false);
  if (!type) {
    r.allow({"t_end", "output_step", "integrator", "verify", "refine", "max_seconds",
             "max_frequency_hz", "time", "load_steps", "tolerance", "max_iterations", "modes",
             "about", "solver", "initial", "control", "arc_length", "max_steps"});
    return std::nullopt;
  }
  bool ok = true;
  if (name && !valid_analysis_name(*name)) {
    r.error("name",
            "must be 1 to 64 letters, digits, '_', '-' or '.', not starting with '.' (it names "
            "the analysis's tables)");
    ok = false;
  }
  if (name) a.name = *name;
  if (load_case) {
    if (load_case->empty()) {
      r.error("load_case", "must not be empty (omit it for the loads without a case)");
      ok = false;
    }
    a.load_case = *load_case;
  }
  if (*type == "transient") {
    a.type = AnalysisSpec::Type::kTransient;
    ok = read_transient(r, a) && ok;
  } else if (*type == "static") {
    a.type = AnalysisSpec::Type::kStatic;
    ok = read_static(r, model, a) && ok;
  } else if (*type == "modal") {
    a.type = AnalysisSpec::Type::kModal;
    ok = read_modal(r, model, a) && ok;
  } else {
    a.type = AnalysisSpec::Type::kBuckling;
    ok = read_buckling(r, model, a) && ok;
  }
  // What the analysis itself refuses, once the reader's checks, which name the key at fault, pass
  // (a transient's options are checked in read_transient).
  std::string problem;
  const bool valid = a.type == AnalysisSpec::Type::kStatic     ? a.statics.IsValid(&problem)
                     : a.type == AnalysisSpec::Type::kModal    ? a.modal.IsValid(&problem)
                     : a.type == AnalysisSpec::Type::kBuckling ? a.buckling.IsValid(&problem)
                                                               : true;
  if (ok && !valid) {
    r.error("type", problem);
    ok = false;
  }
  if (!ok) return std::nullopt;
  return a;
}

}  // namespace beamrail
