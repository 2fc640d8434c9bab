// Reading the "study" object: design variables, sweep plans, optimization plans.
#include <nlopt.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "optimizer/study/design_study.hpp"
#include "optimizer/study/nlopt_setup.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {
namespace {

int response_index(const Study& study, const std::string& name) {
  for (size_t k = 0; k < study.responses.size(); ++k)
    if (study.responses[k].name == name) return static_cast<int>(k);
  return -1;
}

// A response name, or an error naming the ones that exist.
std::optional<int> response_named(ObjectReader& r, const std::string& key, const Json& value,
                                  const Study& study) {
  if (!value.is_string()) {
    r.error(key, "expected a response name, got " + json_type_name(value));
    return std::nullopt;
  }
  const int k = response_index(study, value.get<std::string>());
  if (k >= 0) return k;
  std::string known;
  for (const ResponseSpec& s : study.responses) known += (known.empty() ? "" : ", ") + s.name;
  r.error(key, "unknown response \"" + value.get<std::string>() + "\"" +
                   (known.empty() ? " (the study defines none)" : " (defined: " + known + ")"));
  return std::nullopt;
}

// The number a design-variable pointer addresses must exist in the study document.
bool check_pointer(ObjectReader& r, const std::string& pointer, const Study& study) {
  if (pointer.empty() || pointer[0] != '/') {
    r.error("pointer", "expected a JSON pointer such as \"/scene/sections/tube/outer_diameter\"");
    return false;
  }
  if (pointer.rfind("/study", 0) == 0 && (pointer.size() == 6 || pointer[6] == '/')) {
    r.error("pointer", "a design variable cannot change the design study itself");
    return false;
  }
  try {
    const Json::json_pointer p(pointer);
    if (!study.document.contains(p)) {
      r.error("pointer", "\"" + pointer + "\" does not exist in the study");
      return false;
    }
    if (!study.document.at(p).is_number()) {
      r.error("pointer",
              "\"" + pointer + "\" is " + json_type_name(study.document.at(p)) + ", not a number");
      return false;
    }
  } catch (const std::exception&) {
    r.error("pointer", "\"" + pointer + "\" is not a valid JSON pointer");
    return false;
  }
  return true;
}

std::optional<DesignVariable> read_variable(const Json& value, const Where& where,
                                            const Study& study, DesignStudy::Type type,
                                            SweepPlan::Sampling sampling, Diagnostics& diag) {
  ObjectReader r(value, where, diag);
  if (!r.is_object()) return std::nullopt;
  DesignVariable v;
  v.where = where;
  const auto name = r.string("name", true);
  // One pointer, or several set together (each to factor * value): a rail spacing moves the
  // coordinates of several points at once.
  bool ok = name.has_value();
  if (name && name->empty()) r.error("name", "must not be empty"), ok = false;
  if (const Json* p = r.member("pointer", true)) {
    if (p->is_string()) {
      v.pointers.push_back(p->get<std::string>());
    } else if (p->is_array() && !p->empty()) {
      for (const Json& item : *p) {
        if (!item.is_string()) {
          r.error("pointer", "expected a JSON pointer or an array of JSON pointers");
          ok = false;
          break;
        }
        v.pointers.push_back(item.get<std::string>());
      }
    } else {
      r.error("pointer", "expected a JSON pointer or an array of JSON pointers");
      ok = false;
    }
  } else {
    ok = false;
  }
  for (const std::string& pointer : v.pointers) ok = check_pointer(r, pointer, study) && ok;
  v.factors.assign(v.pointers.size(), 1.0);
  v.offsets.assign(v.pointers.size(), 0.0);
  for (auto [key, out] : {std::pair{"factors", &v.factors}, std::pair{"offsets", &v.offsets}}) {
    if (!r.member(key, false)) continue;
    const auto f = r.numbers(key, true, static_cast<int>(v.pointers.size()));
    if (f)
      *out = *f;
    else
      ok = false;
  }
  const bool grid = type == DesignStudy::Type::kSweep && sampling == SweepPlan::Sampling::kGrid;
  const bool list = type == DesignStudy::Type::kSweep && sampling == SweepPlan::Sampling::kList;
  if (type == DesignStudy::Type::kSensitivity) {
    // The value the study gives: the number at the first pointer, through its link.
    if (!ok) return std::nullopt;
    const Json* at = nullptr;
    try {
      at = &study.document.at(Json::json_pointer(v.pointers[0]));
    } catch (const std::exception&) {
    }
    if (!at || !at->is_number() || v.factors[0] == 0.0) {
      r.error("pointer", "a sensitivity needs a number at the first pointer and a non-zero factor");
      return std::nullopt;
    }
    v.value = (at->get<double>() - v.offsets[0]) / v.factors[0];
    v.name = *name;
    return v;
  }
  if (grid && r.member("values", false)) {
    const auto values = r.numbers("values", true, -1);
    if (!values) return std::nullopt;
    v.values = *values;
  } else if (!list) {
    const auto lower = r.number("lower", true), upper = r.number("upper", true);
    if (!lower || !upper) return std::nullopt;
    if (!(*upper > *lower)) {
      r.error("upper", "must be greater than \"lower\"");
      return std::nullopt;
    }
    v.lower = *lower, v.upper = *upper;
    if (grid) {
      const auto count = r.integer("count", true, 2);
      if (!count) return std::nullopt;
      if (*count > 1000000) {
        r.error("count", "at most 1000000 values per variable");
        return std::nullopt;
      }
      v.count = static_cast<int>(*count);
    }
    if (type == DesignStudy::Type::kOptimize) {
      v.initial = r.number("initial", false);
      if (v.initial && (*v.initial < v.lower || *v.initial > v.upper)) {
        r.error("initial", "must lie between \"lower\" and \"upper\"");
        ok = false;
      }
    }
  }
  if (!ok) return std::nullopt;
  v.name = *name;
  return v;
}

void read_sweep(ObjectReader& r, const Study& study, DesignStudy& d) {
  (void)study;
  const Json* rows = nullptr;
  if (d.sweep.sampling == SweepPlan::Sampling::kList) {
    rows = r.member("rows", true);
    if (rows && (!rows->is_array() || rows->empty())) {
      r.error("rows", "expected a non-empty array of designs (arrays of variable values)");
      return;
    }
    if (!rows) return;
    for (size_t i = 0; i < rows->size(); ++i) {
      const Json& row = (*rows)[i];
      const Where at = r.at("rows") / i;
      if (!row.is_array() || row.size() != d.variables.size()) {
        r.diagnostics().error(at.file, at.pointer,
                              "expected " + std::to_string(d.variables.size()) + " values");
        continue;
      }
      std::vector<double> values;
      for (size_t j = 0; j < row.size(); ++j)
        if (const auto x = read_number(row[j], at / j, r.diagnostics())) values.push_back(*x);
      if (values.size() == row.size()) d.sweep.rows.push_back(values);
    }
  } else if (d.sweep.sampling == SweepPlan::Sampling::kLhs) {
    const auto n = r.integer("samples", true, 1);
    if (n && *n > 10000000) r.error("samples", "at most 1e7 samples");
    d.sweep.samples = static_cast<int>(std::min(n.value_or(0), 10000000L));
    d.sweep.seed = static_cast<unsigned long>(r.integer("seed", false, 0).value_or(1));
  } else {
    double total = 1.0;
    for (const DesignVariable& v : d.variables)
      total *= v.values.empty() ? v.count : static_cast<double>(v.values.size());
    if (total > 1e7) r.error("variables", "the grid has more than 1e7 designs");
  }
}

void read_optimize(ObjectReader& r, const Study& study, DesignStudy& d) {
  OptimizePlan& p = d.optimize;
  if (const Json* objective = r.member("objective", true)) {
    ObjectReader o(*objective, r.at("objective"), r.diagnostics());
    if (o.is_object()) {
      const Json* minimize = o.member("minimize", false);
      const Json* maximize = o.member("maximize", false);
      const Json* target = o.member("target", false);
      if ((minimize != nullptr) + (maximize != nullptr) + (target != nullptr) != 1) {
        r.error("objective", "give exactly one of \"minimize\", \"maximize\" or \"target\"");
      } else if (minimize || maximize) {
        p.goal = minimize ? OptimizePlan::Goal::kMinimize : OptimizePlan::Goal::kMaximize;
        const std::string key = minimize ? "minimize" : "maximize";
        p.response = response_named(o, key, minimize ? *minimize : *maximize, study).value_or(0);
        p.objective_scale = o.positive("scale", false);
      } else {
        p.goal = OptimizePlan::Goal::kTarget;
        p.objective_scale = o.positive("scale", false);
        ObjectReader t(*target, o.at("target"), r.diagnostics());
        if (t.is_object()) {
          if (target->empty()) o.error("target", "expected at least one response: value");
          for (const auto& item : target->items()) {
            const auto value = t.number(item.key(), true);
            const int k = response_index(study, item.key());
            if (k < 0) t.error(item.key(), "unknown response \"" + item.key() + "\"");
            if (value && k >= 0) p.targets.emplace_back(k, *value);
          }
        }
      }
    }
  }
  if (const Json* list = r.member("constraints", false)) {
    if (!list->is_array()) r.error("constraints", "expected an array of constraints");
    for (size_t i = 0; list->is_array() && i < list->size(); ++i) {
      ObjectReader c((*list)[i], r.at("constraints") / i, r.diagnostics());
      if (!c.is_object()) continue;
      Constraint con;
      const Json* name = c.member("response", true);
      int operators = 0;
      for (const auto& [key, kind] :
           {std::pair{">=", Constraint::Kind::kAtLeast}, std::pair{"<=", Constraint::Kind::kAtMost},
            std::pair{"abs<=", Constraint::Kind::kAbsAtMost}}) {
        if (const auto bound = c.number(key, false)) {
          con.kind = kind, con.bound = *bound;
          ++operators;
        }
      }
      if (operators != 1) {
        c.error("response", "give exactly one of \">=\", \"<=\" or \"abs<=\" with a bound");
        continue;
      }
      con.scale = c.positive("scale", false);
      if (!name) continue;
      if (const auto k = response_named(c, "response", *name, study)) {
        con.response = *k;
        p.constraints.push_back(con);
      }
    }
  }
  if (const auto a = r.string("algorithm", false)) {
    if (nlopt_algorithm_from_string(a->c_str()) < 0)
      r.error("algorithm", "unknown NLopt algorithm \"" + *a +
                               "\" (names as in NLopt: LN_COBYLA, LN_BOBYQA, LD_MMA, LD_SLSQP, "
                               "GN_ISRES, GN_DIRECT_L, ...)");
    else
      p.algorithm = *a;
  }
  if (const auto a = r.string("local_algorithm", false)) {
    const nlopt_algorithm local = nlopt_algorithm_from_string(a->c_str());
    if (local < 0)
      r.error("local_algorithm", "unknown NLopt algorithm \"" + *a + "\"");
    else if (runs_local_optimizer(local))
      r.error("local_algorithm", "\"" + *a +
                                     "\" runs a local optimizer itself; the local optimizer of an "
                                     "AUGLAG or MLSL algorithm must be a plain one (LN_COBYLA, "
                                     "LD_MMA, LN_BOBYQA, ...)");
    else
      p.local_algorithm = *a;
  }
  p.max_evaluations =
      static_cast<int>(std::min(r.integer("max_evaluations", false, 1).value_or(200), 100000000L));
  p.xtol_rel = r.positive("xtol_rel", false, true).value_or(p.xtol_rel);
  p.ftol_rel = r.positive("ftol_rel", false, true).value_or(p.ftol_rel);
  p.max_seconds = r.positive("max_seconds", false, true).value_or(0.0);
  p.starts = static_cast<int>(std::min(r.integer("starts", false, 1).value_or(1), 100000L));
  p.seed = static_cast<unsigned long>(r.integer("seed", false, 0).value_or(1));
  p.gradient_step = r.positive("gradient_step", false).value_or(p.gradient_step);
  if (const auto g = r.choice("gradient", false, {"exact", "fd"}))
    p.gradient = *g == "fd" ? OptimizePlan::Gradient::kDifferences : OptimizePlan::Gradient::kExact;
  using Warned = OptimizePlan::WarnedDesigns;
  if (const auto w = r.choice(
          "warned_designs", false,
          {warned_designs_name(Warned::kInfeasible), warned_designs_name(Warned::kAccept)}))
    p.warned_designs =
        *w == warned_designs_name(Warned::kAccept) ? Warned::kAccept : Warned::kInfeasible;
}

void read_work_precision(ObjectReader& r, const Study& study, DesignStudy& d) {
  WorkPrecisionPlan& p = d.work_precision;
  if (find_analysis(study, AnalysisSpec::Type::kTransient) < 0 &&
      study.document.contains("analyses"))
    r.error("type", "a work-precision study needs a transient analysis in \"analyses\"");
  if (const Json* methods = r.member("methods", true)) {
    if (!methods->is_array() || methods->empty()) {
      r.error("methods", "expected a non-empty array of integrator settings");
    } else {
      for (size_t i = 0; i < methods->size(); ++i) {
        const Where at = r.at("methods") / i;
        const Json& m = (*methods)[i];
        if (m.is_object() && (m.contains("rtol") || m.contains("atol"))) {
          r.diagnostics().error(at.file, at.pointer,
                                "tolerances come from \"rtols\" and \"atol_scale\"");
          continue;
        }
        WorkPrecisionPlan::Method method;
        read_integrator(m, at, r.diagnostics(), method.integrator);
        const IntegratorOptions& io = method.integrator;
        method.label = method_name(io.method);
        if (!io.table.empty()) method.label.append(" ").append(io.table);
        if (m.is_object() && m.contains("max_order"))
          method.label.append(" order<=").append(std::to_string(io.max_order));
        if (!io.about.empty()) method.label.append(" about ").append(io.about);
        // Labels tell the methods apart: %g's six digits, or as many as read back as the number
        // (fixed steps of 1e-4 and 1.0000001e-4 were one label over two rows of different error).
        if (io.max_frequency_hz > 0.0)
          method.label.append(" band ").append(shortest(io.max_frequency_hz, 6)).append(" Hz");
        if (io.choose_band) method.label += " band auto";
        if (io.fixed_step > 0.0)
          method.label.append(" fixed_step ").append(shortest(io.fixed_step, 6)).append(" s");
        if (io.linear_solver != LinearSolverKind::kAuto)
          method.label.append(io.linear_solver == LinearSolverKind::kDense ? " dense" : " sparse");
        p.methods.push_back(method);
      }
    }
  }
  if (const auto rtols = r.numbers("rtols", true, -1)) {
    for (size_t i = 0; i < rtols->size(); ++i)
      if (!((*rtols)[i] > 0.0)) {
        const Where at = r.at("rtols") / i;
        r.diagnostics().error(at.file, at.pointer, "tolerances must be > 0");
      }
    p.rtols = *rtols;
  }
  p.atol_scale = r.positive("atol_scale", false).value_or(p.atol_scale);
  p.reference.rtol = 1e-11;
  p.reference.atol = 1e-12;
  if (const Json* reference = r.member("reference", false))
    read_integrator(*reference, r.at("reference"), r.diagnostics(), p.reference);
  p.max_seconds = r.positive("max_seconds", false).value_or(p.max_seconds);
  p.target_error = r.positive("target_error", false).value_or(p.target_error);
}

}  // namespace

std::optional<DesignStudy> read_design_study(const Json& value, const Where& where,
                                             const Study& study, Diagnostics& diag) {
  const size_t errors_before = diag.size();
  DesignStudy d;
  {
    ObjectReader r(value, where, diag);
    if (!r.is_object()) return std::nullopt;
    const auto type =
        r.choice("type", true, {"sweep", "optimize", "work_precision", "sensitivity"});
    if (!type) {
      r.allow({"variables",
               "sampling",
               "samples",
               "seed",
               "rows",
               "objective",
               "constraints",
               "algorithm",
               "local_algorithm",
               "max_evaluations",
               "xtol_rel",
               "ftol_rel",
               "max_seconds",
               "starts",
               "gradient_step",
               "gradient",
               "methods",
               "rtols",
               "atol_scale",
               "reference",
               "target_error",
               "warned_designs",
               "check",
               "check_step",
               "max_seconds_per_design"});
      return std::nullopt;
    }
    if (*type == "work_precision") {
      d.type = DesignStudy::Type::kWorkPrecision;
      read_work_precision(r, study, d);
      return diag.size() > errors_before ? std::nullopt : std::optional<DesignStudy>(d);
    }
    d.type = *type == "sweep"         ? DesignStudy::Type::kSweep
             : *type == "sensitivity" ? DesignStudy::Type::kSensitivity
                                      : DesignStudy::Type::kOptimize;
    if (d.type == DesignStudy::Type::kSweep) {
      const auto s = r.choice("sampling", false, {"grid", "list", "lhs"});
      if (s)
        d.sweep.sampling = *s == "grid"   ? SweepPlan::Sampling::kGrid
                           : *s == "list" ? SweepPlan::Sampling::kList
                                          : SweepPlan::Sampling::kLhs;
    }
    const Json* vars = r.member("variables", true);
    if (vars && (!vars->is_array() || vars->empty())) {
      r.error("variables", "expected a non-empty array of design variables");
    } else if (vars) {
      std::set<std::string> names;
      for (const ResponseSpec& s : study.responses) names.insert(s.name);
      for (size_t i = 0; i < vars->size(); ++i) {
        const Where at = r.at("variables") / i;
        auto v = read_variable((*vars)[i], at, study, d.type, d.sweep.sampling, diag);
        if (!v) continue;
        if (!names.insert(v->name).second)
          diag.error(at.file, (at / "name").pointer,
                     "\"" + v->name + "\" is already the name of a variable or response");
        d.variables.push_back(*v);
      }
    }
    d.max_seconds_per_design = r.positive("max_seconds_per_design", false).value_or(0.0);
    if (d.type == DesignStudy::Type::kSweep) {
      read_sweep(r, study, d);
    } else if (d.type == DesignStudy::Type::kSensitivity) {
      d.sensitivity.check = r.boolean("check", false).value_or(false);
      d.sensitivity.check_step = r.positive("check_step", false).value_or(d.sensitivity.check_step);
    } else {
      read_optimize(r, study, d);
    }
    // NLopt refuses some combinations (a missing algorithm, constraints an algorithm cannot take
    // inside a wrapper) only when it runs: find out now instead of after the first evaluations.
    if (d.type == DesignStudy::Type::kOptimize && diag.size() == errors_before) {
      const std::string refusal = nlopt_refusal(d.optimize, d.variables);
      if (!refusal.empty())
        r.error(!value.contains("algorithm") && value.contains("local_algorithm")
                    ? "local_algorithm"
                    : "algorithm",
                refusal);
    }
  }
  if (diag.size() > errors_before) return std::nullopt;
  return d;
}

}  // namespace beamrail
