#include "optimizer/run/sensitivities.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numbers>

#include "core/analysis/sensitivity.hpp"
#include "core/model/element_kinds.hpp"
#include "optimizer/run/expressions.hpp"
#include "optimizer/run/number_text.hpp"
#include "optimizer/run/responses.hpp"

namespace beamrail {
namespace {

// The warning of an eigenvalue response (`what`: `frequency response "f1"`) whose derivative
// EigenvalueDerivatives::crossing qualifies, "" for none (0: alone; 3: a cluster that stays
// repeated, whose derivative is its members' own).
std::string crossing_warning(const std::string& what, int mode, int crossing, bool buckling) {
  const std::string is = what + " (mode " + std::to_string(mode) + ") is ";
  switch (crossing) {
    case 1:
      return is + "near a crossing of modes: its derivative changes quickly with the design";
    case 2:
      return is +
             (buckling ? "a repeated factor" : "on a crossing of modes (a repeated frequency)") +
             ": its derivative is the directional one as the variables grow";
    case 4:
      return is +
             "repeated with modes beyond those computed (those asked for and two more): its "
             "derivative is not known (NaN); ask the analysis for more modes";
    default:
      return "";
  }
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

template <class A, class B>
bool same_topology(const ModelT<A>& a, const ModelT<B>& b) {
  bool same = a.n_dofs == b.n_dofs && a.bodies.size() == b.bodies.size() &&
              a.loads.size() == b.loads.size() && a.free_bodies == b.free_bodies;
  for_each_element_kind([&](auto kind) {
    same = same && decltype(kind)::elements(a).size() == decltype(kind)::elements(b).size();
  });
  return same;
}

// Whether the design direction moves a breakpoint of a load's time function (a step's time, a
// ramp's ends, a table's times) that lies at time t: the load factor has a kink or a jump there,
// and its derivative with respect to that parameter is one-sided.
bool moves_breakpoint_at(const DualModel& direction, double t) {
  const auto here = [t](const HyperDual& x) { return x.b != 0.0 && x.v == t; };
  for (const LoadT<HyperDual>& load : direction.loads) {
    const TimeFunctionT<HyperDual>& f = load.time;
    using Type = TimeFunctionT<HyperDual>::Type;
    if ((f.type == Type::kStep && here(f.at)) ||
        (f.type == Type::kRamp && (here(f.from) || here(f.to))) ||
        (f.type == Type::kTable && std::any_of(f.t.begin(), f.t.end(), here)))
      return true;
  }
  return false;
}

class Sensitivities {
 public:
  Sensitivities(const Study& design, const Evaluation& ev) : design_(design), ev_(ev) {}

  ResponseSensitivities run(const std::vector<DualModel>& directions);

 private:
  // Fills the single column of out.jacobian with the derivatives along variable j (the design's
  // model along it: `direction`); false (with out.message) when it cannot.
  bool variable(int j, const DualModel& direction, ResponseSensitivities& out);

  const Study& design_;
  const Evaluation& ev_;
  std::map<std::string, std::unique_ptr<EquilibriumSensitivity>> equilibria_;
};

ResponseSensitivities Sensitivities::run(const std::vector<DualModel>& directions) {
  ResponseSensitivities out;
  const int nr = static_cast<int>(design_.responses.size());
  const int nv = static_cast<int>(directions.size());
  out.jacobian = Eigen::MatrixXd::Constant(nr, nv, kNaN);
  if (!ev_.states) {
    out.message = "the evaluation kept no states";
    return out;
  }
  const EvaluationStates& states = *ev_.states;
  // What has no exact derivative.
  for (int k = 0; k < nr; ++k) {
    const ResponseSpec& r = design_.responses[k];
    if (std::isnan(ev_.responses[k])) continue;
    if (r.quantity == ResponseSpec::Quantity::kPeakDisplacement) {
      out.message =
          "response \"" + r.name +
          "\" (the peak of a transient) has no exact derivative: use \"gradient\": \"fd\"";
      return out;
    }
    if (r.quantity == ResponseSpec::Quantity::kFrequency && r.analysis >= 0 &&
        states.analyses[r.analysis].nonsymmetric) {
      out.message = "response \"" + r.name +
                    "\" is a frequency of a non-symmetric eigenproblem (torques of fixed "
                    "direction or follower loads): no exact derivative; use \"gradient\": "
                    "\"fd\"";
      return out;
    }
  }
  // One factorization per equilibrium the responses depend on.
  for (const auto& [key, e] : states.equilibria) {
    if (!e.result.ok) continue;
    auto s = std::make_unique<EquilibriumSensitivity>(*e.model, *e.data, e.time, 1.0);
    equilibria_.emplace(key, std::move(s));
  }
  // The variables in parallel (each writes its own column, warnings and message); one thread
  // when already inside a parallel batch.
  std::vector<ResponseSensitivities> per(nv);
  std::vector<char> done(nv, 0);
#pragma omp parallel for schedule(dynamic, 1) if (nv > 1)
  for (int j = 0; j < nv; ++j) {
    per[j].jacobian = Eigen::MatrixXd::Constant(nr, 1, kNaN);
    try {  // nothing may leave the parallel region
      done[j] = variable(j, directions[j], per[j]);
    } catch (const std::exception& e) {
      per[j].message = std::string("the sensitivities failed: ") + e.what();
      done[j] = 0;
    }
  }
  for (int j = 0; j < nv; ++j) {
    if (!done[j]) {
      out.message = per[j].message;
      out.jacobian.setConstant(kNaN);
      return out;
    }
    out.jacobian.col(j) = per[j].jacobian.col(0);
    for (std::string& w : per[j].warnings) out.warnings.push_back(std::move(w));
  }
  chain_expression_derivatives(design_, ev_.responses, out.jacobian, &out.warnings);
  for (int k = 0; k < nr; ++k) {
    if (std::isnan(ev_.responses[k])) {
      out.jacobian.row(k).setConstant(kNaN);
      continue;
    }
    // A finite response with a derivative that is not: never handed on as a gradient.
    for (int j = 0; j < nv; ++j)
      if (!std::isfinite(out.jacobian(k, j))) {
        out.message = "the derivative of response \"" + design_.responses[k].name +
                      "\" with respect to variable " + std::to_string(j + 1) + " is not finite (" +
                      format_number(out.jacobian(k, j)) + ")";
        out.jacobian.setConstant(kNaN);
        return out;
      }
  }
  out.ok = true;
  return out;
}

bool Sensitivities::variable(int j, const DualModel& direction, ResponseSensitivities& out) {
  if (!same_topology(direction, design_.model)) {
    out.message = "variable " + std::to_string(j + 1) +
                  " changes the scene's bodies or elements (a segment count, a fixed flag): no "
                  "derivative";
    return false;
  }
  const EvaluationStates& states = *ev_.states;
  const int nr = static_cast<int>(design_.responses.size());
  auto column = out.jacobian.col(0);

  // du/dp of each equilibrium, on its load case's models.
  std::map<std::string, Eigen::VectorXd> v;
  // Per load case, the model along the variable an analysis of the case sees.
  std::map<std::string, DualModel> case_models;
  const auto models_of = [&](const std::string& load_case) -> const DualModel& {
    auto it = case_models.find(load_case);
    if (it == case_models.end())
      it = case_models.emplace(load_case, model_for_case(direction, load_case)).first;
    return it->second;
  };
  const auto state_derivative = [&](const std::string& key) -> const Eigen::VectorXd* {
    if (key.empty()) return nullptr;
    auto it = v.find(key);
    if (it != v.end()) return &it->second;
    const EvaluationStates::Equilibrium& e = states.equilibria.at(key);
    const EquilibriumSensitivity& s = *equilibria_.at(key);
    if (!s.failure().empty()) {
      out.message = s.failure();
      return nullptr;
    }
    return &v.emplace(key, s.state_derivative({&models_of(e.load_case)})).first->second;
  };

  for (size_t i = 0; i < design_.analyses.size(); ++i) {
    const EvaluationStates::Analysis& a = states.analyses[i];
    if (!a.ok) continue;
    const AnalysisSpec& spec = design_.analyses[i];
    const int index = static_cast<int>(i);
    bool reads = false;
    for (const ResponseSpec& r : design_.responses) reads = reads || r.analysis == index;
    if (!reads) continue;
    const Eigen::VectorXd* dv = state_derivative(a.equilibrium);
    if (!a.equilibrium.empty() && !dv) return false;
    if (spec.type != AnalysisSpec::Type::kTransient && std::isfinite(a.time) &&
        moves_breakpoint_at(models_of(spec.load_case), a.time))
      out.warnings.push_back("analysis \"" + spec.name + "\" reads the loads at t = " +
                             format_number(a.time) + ", where variable " + std::to_string(j + 1) +
                             " moves a breakpoint of a load's time function: its derivatives "
                             "there are one-sided (the load factor has a kink or a jump)");
    const Eigen::VectorXd none;
    const Eigen::VectorXd& du = dv ? *dv : none;
    switch (spec.type) {
      case AnalysisSpec::Type::kStatic: {
        const EvaluationStates::Equilibrium& e = states.equilibria.at(a.equilibrium);
        std::vector<double> d(nr, kNaN);
        static_response_derivatives(design_, index, *e.model, *e.data, models_of(spec.load_case),
                                    du, d, &out.warnings);
        for (int k = 0; k < nr; ++k)
          if (design_.responses[k].analysis == index) column(k) = d[k];
        break;
      }
      case AnalysisSpec::Type::kModal: {
        const EigenvalueDerivatives d =
            eigenvalue_derivatives(*a.model, *a.data, {&models_of(spec.load_case)}, du, a.time,
                                   a.load_factor, a.eigenvalues, a.shapes, a.complete);
        for (int k = 0; k < nr; ++k) {
          const int m = a.response_mode[k];
          if (m < 0) continue;
          // f = sqrt(lambda) / (2 pi): df = dlambda / (8 pi^2 f).
          const double f = std::sqrt(a.eigenvalues[m]) / (2.0 * std::numbers::pi);
          column(k) = d.values[m] / (8.0 * std::numbers::pi * std::numbers::pi * f);
          if (std::string w =
                  crossing_warning("frequency response \"" + design_.responses[k].name + "\"",
                                   m + 1, d.crossing[m], false);
              !w.empty())
            out.warnings.push_back(std::move(w));
        }
        break;
      }
      case AnalysisSpec::Type::kBuckling: {
        const auto [reference, scaled] = buckling_models(direction, spec.load_case);
        const EigenvalueDerivatives d =
            buckling_factor_derivatives(*a.reference, *a.data, reference, scaled, du, a.time,
                                        a.eigenvalues, a.shapes, a.complete);
        for (int k = 0; k < nr; ++k) {
          const int m = a.response_mode[k];
          if (m < 0) continue;
          column(k) = d.values[m];
          if (std::string w =
                  crossing_warning("buckling factor \"" + design_.responses[k].name + "\"", m + 1,
                                   d.crossing[m], true);
              !w.empty())
            out.warnings.push_back(std::move(w));
        }
        break;
      }
      case AnalysisSpec::Type::kTransient:
        break;  // peaks were refused above; nothing else reads a transient
    }
  }
  for (int k = 0; k < nr; ++k)
    if (design_.responses[k].quantity == ResponseSpec::Quantity::kMass)
      column(k) = mass_response(direction, design_.responses[k]).b;
  return true;
}

}  // namespace

ResponseSensitivities response_sensitivities(const Study& design, const Evaluation& ev,
                                             const std::vector<DualModel>& directions) {
  Sensitivities s(design, ev);
  ResponseSensitivities out;
  try {
    out = s.run(directions);
  } catch (const std::exception& e) {
    out = ResponseSensitivities();
    out.message = std::string("the sensitivities failed: ") + e.what();
  }
  // One warning per text.
  std::vector<std::string> unique;
  for (std::string& w : out.warnings)
    if (std::find(unique.begin(), unique.end(), w) == unique.end()) unique.push_back(std::move(w));
  out.warnings = std::move(unique);
  return out;
}

}  // namespace beamrail
