#include "optimizer/batch/optimize.hpp"

#include <nlopt.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <set>

#include "core/analysis/stop_request.hpp"
#include "optimizer/batch/nlopt_setup.hpp"
#include "optimizer/batch/progress.hpp"
#include "optimizer/batch/sampling.hpp"
#include "optimizer/cli/interruption.hpp"
#include "optimizer/output/batch_table.hpp"
#include "optimizer/output/summary.hpp"
#include "optimizer/output/tables.hpp"
#include "optimizer/output/version.hpp"
#include "optimizer/run/designs.hpp"

namespace beamrail {
namespace {

// Objective and constraint values given to NLopt for a design that failed or is invalid.
constexpr double kPenalty = 1e30;
// A constraint counts as met up to this fraction of its bound.
constexpr double kFeasibility = 1e-9;
// A constraint of a reported design is "active" when its relative margin (the margin over |bound|,
// or the margin itself for a bound of 0) is within max(kActiveFloor, kActiveFactor * xtol_rel) of
// zero. NLopt stops once a step moves the scaled variables (in [0, 1]) by less than xtol_rel of
// their value; a constraint the optimum rests on is then met to about its sensitivity (relative
// change of the constraint per relative change of a variable: 1 for a frequency ~ d, 3 for a
// stress ~ 1/d^3) times that step. The factor 10 covers sensitivities up to 10; the floor covers
// the rounding of the responses (modal frequencies resolve to ~1e-8 and worse, see "Guarantees")
// and NLopt's own constraint tolerance (1e-8, below). summary.json and best.json give the
// tolerance used ("active_tolerance").
constexpr double kActiveFloor = 1e-6;
constexpr double kActiveFactor = 10.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool needs_gradient(const std::string& algorithm) {
  return algorithm.size() > 2 && algorithm[1] == 'D';
}

struct Record {
  int start = 0, evaluation = 0;
  Design x;
  DesignOutcome outcome;
  double objective = kPenalty;
  bool feasible = false;
};

class Optimization {
 public:
  Optimization(const Study& study, const RunSettings& settings)
      : study_(study),
        plan_(study.design->optimize),
        variables_(study.design->variables),
        evaluator_(study),
        settings_(settings),
        progress_(static_cast<long>(plan_.max_evaluations) * plan_.starts, settings.quiet) {}

  int run();

 private:
  struct Start {
    Optimization* self = nullptr;
    int index = 0;  // 1-based
    // Distinct designs of this start -> evaluation number: its rows of history.csv, what its
    // design budget (max_evaluations) counts.
    std::map<Design, int> numbers;
    nlopt_opt opt = nullptr;  // while it runs
    nlopt_result result = NLOPT_SUCCESS;
    std::string message;   // NLopt's own message on an error
    bool stopped = false;  // stopped by us (a stop request or a write error)
    // Stopped by us because NLopt's next call needed more designs than the budget had left
    // (budget_needed of them); its result is then reported as MAXEVAL_REACHED.
    bool budget_spent = false;
    long budget_needed = 0;
    int nlopt_evaluations = 0;
    double objective_scale = 1.0;  // NLopt sees objective / this: |objective| at the start point
  };
  struct ConstraintRef {
    Start* start;
    int j;
  };

  // An evaluated design the optimization may use: ok, and without warnings unless they are
  // accepted ("warned_designs").
  bool usable(const DesignOutcome& o) const;
  double objective_of(const DesignOutcome& o) const;
  double constraint_of(const DesignOutcome& o, int j) const;
  bool feasible(const DesignOutcome& o) const;
  double active_tolerance() const { return std::max(kActiveFloor, kActiveFactor * plan_.xtol_rel); }
  // Per constraint: response, type, bound, value, margin, relative margin, active, satisfied.
  nlohmann::json constraint_report(const DesignOutcome& o) const;
  // What the progress line shows of a feasible record: "mass 16.32" (the objective's response) or
  // "objective 0.0012" (a target).
  std::string best_text(const Record& r) const;
  void show_progress();

  // The outcomes of designs xs for a start, evaluated in parallel where new, recorded in order.
  // A call is evaluated whole or not at all: nullopt (nothing evaluated, NLopt told to stop) when
  // the designs new to the start would take it beyond its budget of max_evaluations designs.
  // With `sensitivities`, new designs are evaluated with their exact derivatives (jacobians_).
  std::optional<std::vector<DesignOutcome>> outcomes(Start& start, const std::vector<Design>& xs,
                                                     bool parallel, bool sensitivities);
  // The outcome of x with the derivatives of its responses (null when it has none: the reason is
  // counted); nullopt beyond the start's design budget.
  std::optional<std::pair<DesignOutcome, std::shared_ptr<const Eigen::MatrixXd>>> with_derivatives(
      Start& start, const Design& x);

  // What NLopt minimizes or bounds: which = -1 the objective, j >= 0 constraint j (as
  // constraint_of); kPenalty for a design that is not usable.
  double value_of(const DesignOutcome& o, int which) const;
  // d value_of / d responses; false when there is none (a penalty).
  bool partials_of(const DesignOutcome& o, int which, Eigen::VectorXd& d) const;
  // Value and (when grad != nullptr) gradient of value_of(outcome, which) at x: exact (the design
  // sensitivities) or by differences inside the bounds (central, or second-order one-sided at a
  // bound).
  double value_and_gradient(Start& start, const double* x, double* grad, int which);

  // NLopt's view: scaled variables s in [0, 1]^n (scaled_variable) and the value divided by
  // `scale`; gradient by the chain rule.
  double scaled_value(Start& start, const double* s, double* grad, double scale, int which);
  static double objective_callback(unsigned n, const double* x, double* grad, void* data);
  static double constraint_callback(unsigned n, const double* x, double* grad, void* data);

  // Whether NLopt's gradients are the design sensitivities.
  bool exact_gradients() const {
    return needs_gradient(plan_.algorithm) && plan_.gradient == OptimizePlan::Gradient::kExact;
  }
  void record_derivatives(const Design& x, const DesignOutcome& o, ResponseSensitivities& s);
  void run_start(Start& start, const Design& x0);
  std::vector<Design> start_points() const;
  CsvRow row(const Record& r) const;
  std::string stop_reason(const Start& st) const;
  int report(const Record* best, const std::vector<Start>& starts, double wall,
             const std::string& history_error) const;

  const Study& study_;
  const OptimizePlan& plan_;
  const std::vector<DesignVariable>& variables_;
  DesignEvaluator evaluator_;
  const RunSettings& settings_;
  Progress progress_;
  BatchTable history_;
  // derivatives.csv (exact gradients): each design's derivatives, read back by --resume
  BatchTable derivatives_;
  std::map<Design, DesignOutcome> cache_;  // every design evaluated, this run or before
  // The exact derivatives of the designs evaluated with them (null: none, see gradient_fallbacks_)
  std::map<Design, std::shared_ptr<const Eigen::MatrixXd>> jacobians_;
  long exact_gradients_ = 0, gradient_fallbacks_ = 0;  // under mutex_
  std::string fallback_reason_;                        // the first design's
  std::set<std::string> sensitivity_warnings_;
  // NLopt sees constraint j as (violation in the response's units) / constraint_scales_[j]
  std::vector<double> constraint_scales_;
  std::vector<Record> records_;
  std::mutex mutex_;
  std::atomic<long> simulated_{0}, failures_{0};
  // The progress line: designs the starts have taken (simulated or from the cache) and the design
  // budget left to them (max_evaluations per start, lowered to what a finished start took).
  std::atomic<long> done_{0}, budget_total_{0};
  double best_objective_ = kPenalty;  // of the feasible records so far (under mutex_)
  std::string best_text_;
  std::atomic<bool> write_failed_{false};
  int threads_ = 1;
};

// Whether the optimization must end now: a stop was requested or history.csv cannot be written.
bool must_stop(const std::atomic<bool>& write_failed) { return stop_requested() || write_failed; }

bool Optimization::usable(const DesignOutcome& o) const {
  return o.status == Status::kOk &&
         (o.warnings == 0 || plan_.warned_designs == OptimizePlan::WarnedDesigns::kAccept);
}

double Optimization::objective_of(const DesignOutcome& o) const {
  if (!usable(o)) return kPenalty;
  double f = 0.0;
  switch (plan_.goal) {
    case OptimizePlan::Goal::kMinimize:
      f = o.responses[plan_.response];
      break;
    case OptimizePlan::Goal::kMaximize:
      f = -o.responses[plan_.response];
      break;
    case OptimizePlan::Goal::kTarget:
      for (const auto& [k, t] : plan_.targets) {
        const double scale = t != 0.0 ? std::abs(t) : 1.0;
        f += std::pow((o.responses[k] - t) / scale, 2);
      }
      break;
  }
  return std::isfinite(f) ? f : kPenalty;
}

double Optimization::constraint_of(const DesignOutcome& o, int j) const {
  const Constraint& c = plan_.constraints[j];
  const double r = o.responses[c.response];
  if (!usable(o) || !std::isfinite(r)) return kPenalty;
  const double scale = c.bound != 0.0 ? std::abs(c.bound) : 1.0;
  switch (c.kind) {
    case Constraint::Kind::kAtLeast:
      return (c.bound - r) / scale;
    case Constraint::Kind::kAtMost:
      return (r - c.bound) / scale;
    default:
      return (std::abs(r) - c.bound) / scale;
  }
}

bool Optimization::feasible(const DesignOutcome& o) const {
  if (!usable(o) || objective_of(o) >= kPenalty) return false;
  for (size_t j = 0; j < plan_.constraints.size(); ++j)
    if (!(constraint_of(o, static_cast<int>(j)) <= kFeasibility)) return false;
  return true;
}

nlohmann::json Optimization::constraint_report(const DesignOutcome& o) const {
  nlohmann::json list = nlohmann::json::array();
  const double tolerance = active_tolerance();
  for (const Constraint& c : plan_.constraints) {
    const double value = o.responses[c.response];
    double margin = 0.0;  // positive: satisfied with room, in the response's units
    const char* type = "";
    switch (c.kind) {
      case Constraint::Kind::kAtLeast:
        margin = value - c.bound, type = ">=";
        break;
      case Constraint::Kind::kAtMost:
        margin = c.bound - value, type = "<=";
        break;
      case Constraint::Kind::kAbsAtMost:
        margin = c.bound - std::abs(value), type = "abs<=";
        break;
    }
    // The negative of constraint_of(): satisfied is what feasible() requires of the constraint.
    const double relative = c.bound != 0.0 ? margin / std::abs(c.bound) : margin;
    const bool finite = std::isfinite(relative);
    list.push_back({{"response", study_.responses[c.response].name},
                    {"type", type},
                    {"bound", c.bound},
                    {"value", json_number(value)},
                    {"margin", json_number(margin)},
                    {"relative_margin", json_number(relative)},
                    {"active", finite && std::abs(relative) <= tolerance},
                    {"satisfied", finite && relative >= -kFeasibility}});
  }
  return list;
}

CsvRow Optimization::row(const Record& r) const {
  CsvRow out{std::to_string(r.start), std::to_string(r.evaluation)};
  for (double x : r.x) out.push_back(format_number(x));
  for (double v : r.outcome.responses) out.push_back(format_number(v));
  out.push_back(format_number(r.objective));
  out.push_back(r.feasible ? "1" : "0");
  out.push_back(status_name(r.outcome.status));
  out.push_back(std::to_string(r.outcome.warnings));
  out.push_back(format_number(r.outcome.wall_seconds));
  out.push_back(r.outcome.message);
  return out;
}

std::string Optimization::best_text(const Record& r) const {
  const auto short_number = [](double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", x);
    return std::string(buf);
  };
  switch (plan_.goal) {
    case OptimizePlan::Goal::kMinimize:
    case OptimizePlan::Goal::kMaximize:
      return study_.responses[plan_.response].name + " " +
             short_number(r.outcome.responses[plan_.response]);
    default:
      return "objective " + short_number(r.objective);
  }
}

void Optimization::show_progress() {
  std::string best;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    best = best_text_;
  }
  progress_.update(done_, failures_, best);
}

std::optional<std::vector<DesignOutcome>> Optimization::outcomes(Start& start,
                                                                 const std::vector<Design>& xs,
                                                                 bool parallel,
                                                                 bool sensitivities) {
  std::vector<DesignOutcome> out(xs.size());
  std::vector<ResponseSensitivities> derivatives(sensitivities ? xs.size() : 0);
  std::vector<char> known(xs.size(), 0);
  std::vector<int> numbers(xs.size());
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // The start's design budget: every design new to the start counts, simulated now or taken
    // from the cache (another start's, or history.csv's on --resume), so that a resumed run stops
    // where the uninterrupted one did. A call that does not fit is not evaluated at all.
    std::set<Design> fresh;
    for (const Design& x : xs)
      if (!start.numbers.count(x)) fresh.insert(x);
    if (start.numbers.size() + fresh.size() > static_cast<size_t>(plan_.max_evaluations)) {
      if (!start.budget_spent) {
        start.budget_spent = true;
        start.budget_needed = static_cast<long>(fresh.size());
      }
      if (start.opt) nlopt_force_stop(start.opt);
      return std::nullopt;
    }
    for (size_t i = 0; i < xs.size(); ++i) {
      auto [it, is_new] =
          start.numbers.try_emplace(xs[i], static_cast<int>(start.numbers.size()) + 1);
      numbers[i] = is_new ? it->second : -it->second;  // negative: this start has its row already
      const auto c = cache_.find(xs[i]);
      if (c != cache_.end()) {
        out[i] = c->second, known[i] = 1;
        if (is_new) ++done_;
      }
    }
  }
  // A design listed twice (a difference point clamped onto the point) is evaluated once.
  std::map<Design, long> first;
  std::vector<long> copy_of(xs.size(), -1);
  for (size_t i = 0; i < xs.size(); ++i) {
    const auto [it, is_new] = first.try_emplace(xs[i], static_cast<long>(i));
    if (!is_new && !known[i]) copy_of[i] = it->second, known[i] = 1;
  }
  const long n = static_cast<long>(xs.size());
  const int threads = static_cast<int>(std::min<long>(threads_, n));
#pragma omp parallel for schedule(dynamic, 1) if (parallel && n > 1) num_threads(threads)
  for (long i = 0; i < n; ++i)
    if (!known[i]) {
      if (must_stop(write_failed_)) {
        out[i].status = Status::kInterrupted;  // not evaluated
        out[i].responses.assign(study_.responses.size(), kNaN);
        continue;
      }
      out[i] = evaluator_.evaluate(xs[i], sensitivities ? &derivatives[i] : nullptr);
      if (out[i].status == Status::kInterrupted) continue;
      ++simulated_;
      if (out[i].status != Status::kOk) ++failures_;
      if (numbers[i] > 0) ++done_;
      show_progress();
    }
  for (size_t i = 0; i < xs.size(); ++i)
    if (copy_of[i] >= 0) out[i] = out[copy_of[i]];
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t i = 0; i < xs.size(); ++i) {
      // An interrupted design is no result: neither cached nor in the history (a resumed run
      // evaluates it).
      if (out[i].status == Status::kInterrupted) continue;
      cache_.try_emplace(xs[i], out[i]);
      if (sensitivities && !known[i]) record_derivatives(xs[i], out[i], derivatives[i]);
      if (numbers[i] < 0) continue;
      Record r{start.index, numbers[i], xs[i], out[i], objective_of(out[i]), feasible(out[i])};
      if (!history_.append(row(r))) write_failed_ = true;
      if (r.feasible && r.objective < best_objective_) {
        best_objective_ = r.objective;
        best_text_ = best_text(r);
      }
      records_.push_back(std::move(r));
    }
  }
  show_progress();
  return out;
}

void Optimization::record_derivatives(const Design& x, const DesignOutcome& o,
                                      ResponseSensitivities& s) {
  // Under mutex_.
  if (s.ok) {
    ++exact_gradients_;
    CsvRow row;
    for (double v : x) row.push_back(format_number(v));
    for (Eigen::Index k = 0; k < s.jacobian.rows(); ++k)
      for (Eigen::Index j = 0; j < s.jacobian.cols(); ++j)
        row.push_back(format_number(s.jacobian(k, j)));
    if (!derivatives_.append(row)) write_failed_ = true;
    jacobians_[x] = std::make_shared<const Eigen::MatrixXd>(std::move(s.jacobian));
    for (std::string& w : s.warnings)
      if (sensitivity_warnings_.size() < 20) sensitivity_warnings_.insert(std::move(w));
  } else {
    jacobians_[x] = nullptr;
    if (o.status != Status::kOk) return;  // a failed design is a penalty: no gradient needed
    ++gradient_fallbacks_;
    if (fallback_reason_.empty()) fallback_reason_ = s.message;
  }
}

std::optional<std::pair<DesignOutcome, std::shared_ptr<const Eigen::MatrixXd>>>
Optimization::with_derivatives(Start& start, const Design& x) {
  const auto o = outcomes(start, {x}, false, true);
  if (!o) return std::nullopt;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = jacobians_.find(x);
    if (it != jacobians_.end()) return std::make_pair((*o)[0], it->second);
  }
  // Evaluated before without its derivatives (another start's difference point, or history.csv
  // on --resume): once more, with them; no new row.
  ResponseSensitivities s;
  const DesignOutcome again = evaluator_.evaluate(x, &s);
  if (again.status == Status::kInterrupted) return std::make_pair((*o)[0], nullptr);
  ++simulated_;
  std::lock_guard<std::mutex> lock(mutex_);
  record_derivatives(x, again, s);
  return std::make_pair((*o)[0], jacobians_[x]);
}

double Optimization::value_of(const DesignOutcome& o, int which) const {
  return which < 0 ? objective_of(o) : constraint_of(o, which);
}

bool Optimization::partials_of(const DesignOutcome& o, int which, Eigen::VectorXd& d) const {
  if (value_of(o, which) >= kPenalty) return false;
  d = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(study_.responses.size()));
  if (which < 0) {
    switch (plan_.goal) {
      case OptimizePlan::Goal::kMinimize:
        d(plan_.response) = 1.0;
        break;
      case OptimizePlan::Goal::kMaximize:
        d(plan_.response) = -1.0;
        break;
      case OptimizePlan::Goal::kTarget:
        for (const auto& [k, t] : plan_.targets) {
          const double scale = t != 0.0 ? std::abs(t) : 1.0;
          d(k) += 2.0 * (o.responses[k] - t) / (scale * scale);
        }
        break;
    }
    return true;
  }
  const Constraint& c = plan_.constraints[which];
  const double scale = c.bound != 0.0 ? std::abs(c.bound) : 1.0;  // as constraint_of
  const double r = o.responses[c.response];
  d(c.response) = c.kind == Constraint::Kind::kAtLeast  ? -1.0 / scale
                  : c.kind == Constraint::Kind::kAtMost ? 1.0 / scale
                                                        : (r < 0.0 ? -1.0 : 1.0) / scale;
  return true;
}

double Optimization::value_and_gradient(Start& start, const double* x, double* grad, int which) {
  const size_t n = variables_.size();
  const Design x0(x, x + n);
  if (grad && plan_.gradient == OptimizePlan::Gradient::kExact) {
    const auto r = with_derivatives(start, x0);
    if (!r) {  // beyond the start's design budget: nothing evaluated, NLopt stops
      std::fill(grad, grad + n, 0.0);
      return kPenalty;
    }
    const double value = value_of(r->first, which);
    Eigen::VectorXd d;
    if (value >= kPenalty || !partials_of(r->first, which, d)) {
      std::fill(grad, grad + n, 0.0);
      return value;
    }
    if (r->second) {
      const Eigen::MatrixXd& jacobian = *r->second;
      bool finite = true;
      for (size_t i = 0; i < n; ++i) {
        grad[i] = 0.0;
        for (Eigen::Index k = 0; k < d.size(); ++k)
          if (d(k) != 0.0) grad[i] += d(k) * jacobian(k, static_cast<Eigen::Index>(i));
        finite = finite && std::isfinite(grad[i]);
      }
      if (finite) return value;
    }
    // No exact derivatives for this design: differences.
  }
  // Difference points inside the bounds: central where x0 +- h fit, else second-order one-sided
  // (x0 -+ h, x0 -+ 2h) at a bound.
  enum class Stencil { kCentral, kBackward, kForward };
  std::vector<Design> points{x0};
  std::vector<double> h(n, 0.0);
  std::vector<Stencil> stencil(n, Stencil::kCentral);
  if (grad) {
    for (size_t i = 0; i < n; ++i) {
      const DesignVariable& v = variables_[i];
      h[i] = plan_.gradient_step * (v.upper - v.lower);
      const bool up = x0[i] + h[i] <= v.upper, down = x0[i] - h[i] >= v.lower;
      stencil[i] = up && down ? Stencil::kCentral : up ? Stencil::kForward : Stencil::kBackward;
      const double s1 = stencil[i] == Stencil::kBackward ? -h[i] : h[i];
      const double s2 = stencil[i] == Stencil::kCentral ? -h[i] : 2.0 * s1;
      Design a = x0, b = x0;
      a[i] = std::clamp(x0[i] + s1, v.lower, v.upper);
      b[i] = std::clamp(x0[i] + s2, v.lower, v.upper);
      points.push_back(a);
      points.push_back(b);
    }
  }
  const std::optional<std::vector<DesignOutcome>> evaluated = outcomes(start, points, true, false);
  if (!evaluated) {  // beyond the start's design budget: nothing evaluated, NLopt stops
    if (grad) std::fill(grad, grad + n, 0.0);
    return kPenalty;
  }
  const std::vector<DesignOutcome>& o = *evaluated;
  const double value = value_of(o[0], which);
  if (grad)
    for (size_t i = 0; i < n; ++i) {
      const double fa = value_of(o[1 + 2 * i], which), fb = value_of(o[2 + 2 * i], which);
      const double a = points[1 + 2 * i][i] - x0[i], b = points[2 + 2 * i][i] - x0[i];
      grad[i] = 0.0;
      if (stencil[i] == Stencil::kCentral && fa < kPenalty && fb < kPenalty && a != b)
        grad[i] = (fa - fb) / (a - b);
      else if (stencil[i] != Stencil::kCentral && value < kPenalty && fa < kPenalty &&
               fb < kPenalty && a != 0.0 && b == 2.0 * a)
        grad[i] = (-3.0 * value + 4.0 * fa - fb) / (2.0 * a);  // a = +-h, b = +-2h
      else if (fa < kPenalty && value < kPenalty && a != 0.0)
        grad[i] = (fa - value) / a;
      else if (fb < kPenalty && value < kPenalty && b != 0.0)
        grad[i] = (fb - value) / b;
    }
  return value;
}

double Optimization::scaled_value(Start& start, const double* s, double* grad, double scale,
                                  int which) {
  const size_t n = variables_.size();
  Design x(n);
  for (size_t i = 0; i < n; ++i) x[i] = physical_variable(variables_[i], s[i]);
  std::vector<double> gx(n, 0.0);
  const double v = value_and_gradient(start, x.data(), grad ? gx.data() : nullptr, which);
  if (grad)
    for (size_t i = 0; i < n; ++i)
      grad[i] = gx[i] * (variables_[i].upper - variables_[i].lower) / scale;
  return v >= kPenalty ? v : v / scale;
}

double Optimization::objective_callback(unsigned, const double* x, double* grad, void* data) {
  auto* start = static_cast<Start*>(data);
  try {
    ++start->nlopt_evaluations;
    Optimization& self = *start->self;
    const double v = self.scaled_value(*start, x, grad, start->objective_scale, -1);
    if (must_stop(self.write_failed_)) {
      start->stopped = true;
      nlopt_force_stop(start->opt);
    }
    return v;
  } catch (...) {
    return kPenalty;  // never throw through NLopt
  }
}

double Optimization::constraint_callback(unsigned, const double* x, double* grad, void* data) {
  auto* ref = static_cast<ConstraintRef*>(data);
  try {
    Optimization& self = *ref->start->self;
    const int j = ref->j;
    // constraint_of is relative to |bound| (or 1): NLopt sees it relative to the constraint's
    // scale.
    const Constraint& c = self.plan_.constraints[j];
    const double relative_to = c.bound != 0.0 ? std::abs(c.bound) : 1.0;
    return self.scaled_value(*ref->start, x, grad, self.constraint_scales_[j] / relative_to, j);
  } catch (...) {
    return kPenalty;
  }
}

std::vector<Design> Optimization::start_points() const {
  std::vector<Design> points;
  bool all_initial = true;
  Design initial;
  for (const DesignVariable& v : variables_) {
    all_initial = all_initial && v.initial.has_value();
    initial.push_back(v.initial.value_or(0.5 * (v.lower + v.upper)));
  }
  if (all_initial) points.push_back(initial);
  const int more = plan_.starts - static_cast<int>(points.size());
  if (more > 0)
    for (Design& d : latin_hypercube(variables_, more, plan_.seed)) points.push_back(d);
  return points;
}

void Optimization::run_start(Start& start, const Design& x0) {
  const NloptSetup setup(plan_, variables_);
  nlopt_opt opt = setup.get();
  nlopt_set_min_objective(opt, objective_callback, &start);
  std::vector<ConstraintRef> refs;
  for (size_t j = 0; j < plan_.constraints.size(); ++j)
    refs.push_back(ConstraintRef{&start, static_cast<int>(j)});
  for (ConstraintRef& ref : refs)
    nlopt_add_inequality_constraint(opt, constraint_callback, &ref, 1e-8);
  // The design budget (max_evaluations designs per start) is enforced in outcomes(); NLopt's own
  // limit on its calls is the same number, which stops a start whose calls keep returning to
  // designs it has evaluated (they cost no budget). Without gradients a call is one design: the
  // two limits coincide.
  nlopt_set_maxeval(opt, plan_.max_evaluations);
  if (plan_.max_seconds > 0) nlopt_set_maxtime(opt, plan_.max_seconds);
  nlopt_srand(plan_.seed + static_cast<unsigned long>(start.index));  // stochastic algorithms

  // The objective's scale: its magnitude at the start point (constraints are already relative to
  // their bounds).
  const std::optional<std::vector<DesignOutcome>> o0 =
      outcomes(start, {x0}, false, exact_gradients());
  const double f0 = o0 ? objective_of((*o0)[0]) : kPenalty;
  start.objective_scale =
      plan_.objective_scale.value_or(f0 < kPenalty && std::abs(f0) > 0.0 ? std::abs(f0) : 1.0);
  Design x(x0.size());
  for (size_t i = 0; i < x0.size(); ++i) x[i] = scaled_variable(variables_[i], x0[i]);
  double f = 0.0;
  start.opt = opt;
  start.result = nlopt_optimize(opt, x.data(), &f);
  if (start.result < 0 && nlopt_get_errmsg(opt)) start.message = nlopt_get_errmsg(opt);
  start.opt = nullptr;
  // Spending the design budget is a normal stop (NLopt returns FORCED_STOP, or whatever it made of
  // the penalty values it got after the stop): reported as NLopt reports its own limit.
  if (start.budget_spent && !start.stopped) start.result = NLOPT_MAXEVAL_REACHED;
  // The start is done: the progress total keeps only the designs it took of its budget.
  std::lock_guard<std::mutex> lock(mutex_);
  budget_total_ -= plan_.max_evaluations - static_cast<long>(start.numbers.size());
  progress_.set_total(budget_total_);
}

// Why a start stopped, in words.
std::string Optimization::stop_reason(const Start& st) const {
  const std::string budget = std::to_string(plan_.max_evaluations);
  switch (st.result) {
    case NLOPT_SUCCESS:
      return "the algorithm's own convergence test was met";
    case NLOPT_STOPVAL_REACHED:
      return "the objective reached NLopt's stopval";
    case NLOPT_FTOL_REACHED:
      return "a step changed the objective by less than ftol_rel (" +
             format_number(plan_.ftol_rel) + ") of its value";
    case NLOPT_XTOL_REACHED:
      return "a step changed every variable, scaled to [0, 1] by its bounds, by less than "
             "xtol_rel (" +
             format_number(plan_.xtol_rel) + ") of its value";
    case NLOPT_MAXEVAL_REACHED:
      if (st.budget_spent)
        return "the design budget is spent: the start had evaluated " +
               std::to_string(st.numbers.size()) + " of its " + budget +
               " designs (max_evaluations) and NLopt's next call needed " +
               std::to_string(st.budget_needed) + " more; beamrail stopped NLopt without it";
      return "NLopt reached its own limit of max_evaluations (" + budget + ") calls" +
             (needs_gradient(plan_.algorithm)
                  ? std::string(" (calls at designs the start had evaluated cost no designs)")
                  : std::string(" (without gradients a call is one design at most)"));
    case NLOPT_MAXTIME_REACHED:
      return "the start ran for max_seconds (" + format_number(plan_.max_seconds) + " s)";
    case NLOPT_ROUNDOFF_LIMITED:
      return "roundoff errors limited NLopt's progress: the best design may not be an optimum";
    case NLOPT_FORCED_STOP:
      return st.stopped ? "beamrail stopped NLopt: a stop was requested (SIGINT, SIGTERM) or "
                          "history.csv could not be written"
                        : "NLopt was forced to stop, not by beamrail";
    case NLOPT_FAILURE:
      return "NLopt failed" + (st.message.empty() ? std::string() : ": " + st.message);
    case NLOPT_INVALID_ARGS:
      return "NLopt refused its arguments" +
             (st.message.empty() ? std::string() : ": " + st.message);
    case NLOPT_OUT_OF_MEMORY:
      return "NLopt ran out of memory";
    default:
      return "NLopt returned " + std::to_string(static_cast<int>(st.result));
  }
}

// What a start's NLopt result means for the study: "" (a normal stop), or a warning, or an error.
struct StopMeaning {
  std::string warning, error;
};

StopMeaning meaning_of(int index, nlopt_result result, bool stopped_by_us,
                       const std::string& nlopt_message) {
  StopMeaning m;
  if (result > 0 || (result == NLOPT_FORCED_STOP && stopped_by_us)) return m;
  const std::string start = "start " + std::to_string(index) + ": ";
  const std::string name = nlopt_result_to_string(result);
  if (result == NLOPT_ROUNDOFF_LIMITED) {
    m.warning = start +
                "NLopt stopped early because roundoff errors limited its progress "
                "(ROUNDOFF_LIMITED): the designs it evaluated are in the history, but the best of "
                "them may not be an optimum";
    return m;
  }
  m.error = start + "NLopt failed (" + name + ")" +
            (nlopt_message.empty() ? std::string() : ": " + nlopt_message);
  return m;
}

int Optimization::report(const Record* best, const std::vector<Start>& starts, double wall,
                         const std::string& history_error) const {
  const int signal = stop_requested();
  std::vector<std::string> warnings = study_.input_warnings, errors;
  bool stopped = false;
  for (const Start& st : starts) {
    const StopMeaning m = meaning_of(st.index, st.result, st.stopped, st.message);
    if (!m.warning.empty()) warnings.push_back(m.warning);
    if (!m.error.empty()) errors.push_back(m.error);
    stopped = stopped || st.stopped;
  }
  if (gradient_fallbacks_ > 0)
    warnings.push_back(std::to_string(gradient_fallbacks_) +
                       " design(s) had no exact derivatives, and their gradients came from "
                       "central differences: " +
                       fallback_reason_);
  for (const std::string& w : sensitivity_warnings_) warnings.push_back("derivatives: " + w);
  const bool interrupted = signal != 0 && stopped;
  std::string status, message;
  if (!history_error.empty()) {
    status = "failed", message = history_error;
  } else if (!errors.empty()) {
    status = "failed";
    for (const std::string& e : errors) message += (message.empty() ? "" : "; ") + e;
  } else if (interrupted) {
    status = "interrupted";
    message = "interrupted by " + signal_name(signal) + " after " +
              std::to_string(records_.size()) + " designs";
  } else if (best) {
    status = "ok";
  } else {
    status = "infeasible";
    message = "no evaluated design satisfies every constraint";
    long warned = 0;
    for (const Record& r : records_)
      warned += r.outcome.status == Status::kOk && r.outcome.warnings > 0;
    if (warned > 0 && plan_.warned_designs == OptimizePlan::WarnedDesigns::kInfeasible)
      message += " (" + std::to_string(warned) +
                 " designs with warnings count as infeasible; their warnings are in the message "
                 "column of history.csv; \"warned_designs\": \"accept\" accepts them)";
  }

  nlohmann::json s;
  s["study"] = study_.name;
  s["file"] = study_.file;
  s["beamrail_version"] = kVersion;
  s["type"] = "optimize";
  s["algorithm"] = plan_.algorithm;
  s["optimizer"] = NloptSetup(plan_, variables_).description();
  s["status"] = status;
  s["message"] = message;
  s["warnings"] = warnings;
  s["max_evaluations"] = plan_.max_evaluations;
  s["active_tolerance"] = active_tolerance();
  nlohmann::json per_start = nlohmann::json::array();
  for (const Start& st : starts) {
    // The start's best feasible design; ties go to its earliest evaluation (records_ is sorted).
    const Record* own = nullptr;
    for (const Record& r : records_)
      if (r.start == st.index && r.feasible && (!own || r.objective < own->objective)) own = &r;
    nlohmann::json start_best = nullptr;
    if (own) {
      nlohmann::json vars = nlohmann::json::object();
      for (size_t i = 0; i < variables_.size(); ++i) vars[variables_[i].name] = own->x[i];
      start_best = {{"evaluation", own->evaluation},
                    {"objective", json_number(own->objective)},
                    {"variables", vars}};
    }
    per_start.push_back({{"start", st.index},
                         {"nlopt_result", nlopt_result_to_string(st.result)},
                         {"stop_reason", stop_reason(st)},
                         {"nlopt_evaluations", st.nlopt_evaluations},
                         {"designs", st.numbers.size()},
                         {"best", start_best}});
  }
  s["starts"] = per_start;
  // The problem NLopt sees.
  nlohmann::json scaling;
  nlohmann::json vars = nlohmann::json::array(), cons = nlohmann::json::array();
  for (const DesignVariable& v : variables_)
    vars.push_back({{"name", v.name}, {"lower", v.lower}, {"upper", v.upper}});
  for (size_t j = 0; j < plan_.constraints.size(); ++j)
    cons.push_back({{"response", study_.responses[plan_.constraints[j].response].name},
                    {"scale", constraint_scales_.at(j)}});
  nlohmann::json objective_scales = nlohmann::json::array();
  for (const Start& st : starts) objective_scales.push_back(st.objective_scale);
  scaling["variables"] = vars;
  scaling["variables_seen_as"] = "(x - lower) / (upper - lower), in [0, 1]";
  scaling["objective_scale"] = objective_scales;
  scaling["objective_seen_as"] = "objective / objective_scale (per start)";
  scaling["constraints"] = cons;
  scaling["constraints_seen_as"] =
      "violation in the response's units / scale, <= 0 when met (value - bound for <=, bound - "
      "value for >=, |value| - bound for abs<=)";
  s["scaling"] = scaling;
  if (needs_gradient(plan_.algorithm)) {
    nlohmann::json g;
    g["method"] = exact_gradients() ? "exact" : "fd";
    if (exact_gradients()) {
      g["designs_with_exact_derivatives"] = exact_gradients_;
      g["designs_by_differences"] = gradient_fallbacks_;
      if (gradient_fallbacks_ > 0) g["why_differences"] = fallback_reason_;
    } else {
      g["step"] = plan_.gradient_step;
    }
    s["gradient"] = g;
  }
  s["designs_simulated"] = simulated_.load();
  s["designs_failed"] = failures_.load();
  long warned = 0;
  for (const Record& r : records_) warned += r.outcome.warnings > 0;
  s["designs_with_warnings"] = warned;
  s["warned_designs"] =
      plan_.warned_designs == OptimizePlan::WarnedDesigns::kAccept ? "accept" : "infeasible";
  s["designs_in_history"] = records_.size();
  s["ranks"] = 1;  // an optimization runs in one process (rank 0 under mpirun)
  s["threads"] = threads_;
  s["wall_seconds"] = wall;
  s["evaluations_per_second"] = wall > 0 ? static_cast<double>(simulated_.load()) / wall : 0.0;
  s["model"] = model_summary(study_.model);
  std::string error;
  bool ok = true;
  if (best) {
    nlohmann::json b;
    b["objective"] = json_number(best->objective);
    b["start"] = best->start;
    b["evaluation"] = best->evaluation;
    nlohmann::json vars = nlohmann::json::object(), resp = nlohmann::json::object();
    for (size_t i = 0; i < variables_.size(); ++i) vars[variables_[i].name] = best->x[i];
    for (size_t k = 0; k < study_.responses.size(); ++k)
      resp[study_.responses[k].name] = json_number(best->outcome.responses[k]);
    b["variables"] = vars;
    b["responses"] = resp;
    b["constraints"] = constraint_report(best->outcome);
    b["active_tolerance"] = active_tolerance();
    if (status == "ok") {
      s["best"] = b;
      s["responses"] = resp;
      Json scene = evaluator_.document(best->x);
      scene["name"] = study_.name + "_best";
      scene["description"] = "The best design found by " + plan_.algorithm + " for study \"" +
                             study_.name + "\" (start " + std::to_string(best->start) +
                             ", evaluation " + std::to_string(best->evaluation) + ").";
      ok =
          write_file_atomically(settings_.output / "best.json", b.dump(2) + "\n", &error) &&
          write_file_atomically(settings_.output / "best_scene.json", scene.dump(2) + "\n", &error);
    } else {
      // An unfinished or failed optimization names no best design (no best.json): the best
      // feasible design it evaluated is given for information.
      s["best_evaluated"] = b;
    }
  }
  ok = ok && write_file_atomically(settings_.output / "summary.json", s.dump(2) + "\n", &error);
  for (size_t k = study_.input_warnings.size(); k < warnings.size(); ++k)
    std::cerr << "warning: " << warnings[k] << "\n";
  if (!ok) {
    std::cerr << "beamrail: " << error << "\n";
    return 1;
  }
  const std::string history = (settings_.output / "history.csv").string();
  if (status == "failed") {
    std::cerr << "beamrail: " << study_.name << " failed: " << message << "\n(" << records_.size()
              << " designs evaluated are in " << history << "; no best.json is written)\n";
    return 1;
  }
  if (status == "interrupted") {
    std::cerr << "beamrail: " << study_.name << " interrupted by " << signal_name(signal) << ": "
              << records_.size() << " designs are in " << history
              << "; continue with: " << settings_.command << " --resume\n";
    return interrupted_exit_status(signal);
  }
  if (!best) {
    std::cerr << "beamrail: " << study_.name << ": " << message << " (" << records_.size()
              << " designs evaluated); see " << history << "\n";
    return 1;
  }
  std::cout << study_.name << ": best objective " << format_number(best->objective) << " at";
  for (size_t i = 0; i < variables_.size(); ++i)
    std::cout << " " << variables_[i].name << " = " << format_number(best->x[i]);
  std::cout << " (" << records_.size() << " designs, " << wall << " s) -> "
            << settings_.output.string() << "\n";
  return 0;
}

int Optimization::run() {
  const auto wall_start = std::chrono::steady_clock::now();
  if (!evaluator_.setup_failure().empty())
    return fail_before_designs(study_, settings_.output, "optimize", evaluator_.setup_failure());
  CsvRow header{"start", "evaluation"};
  for (const DesignVariable& v : variables_) header.push_back(v.name);
  for (const ResponseSpec& r : study_.responses) header.push_back(r.name);
  for (const char* c : {"objective", "feasible", "status", "warnings", "wall_s", "message"})
    header.push_back(c);
  // A best design of an earlier run must not stand beside this run's history.
  for (const char* stale : {"best.json", "best_scene.json"}) {
    std::error_code ec;
    std::filesystem::remove(settings_.output / stale, ec);
  }
  std::vector<CsvRow> existing;
  std::string error;
  if (const int status = open_exit_status(history_.open(settings_.output / "history.csv", header,
                                                        settings_.resume, &existing, &error),
                                          error))
    return status;
  // Earlier evaluations become the cache that NLopt's replayed path hits.
  const size_t nv = variables_.size(), nr = study_.responses.size();
  for (const CsvRow& r : existing) {
    Design x;
    for (size_t i = 0; i < nv; ++i) x.push_back(std::strtod(r[2 + i].c_str(), nullptr));
    DesignOutcome o;
    for (size_t k = 0; k < nr; ++k)
      o.responses.push_back(std::strtod(r[2 + nv + k].c_str(), nullptr));
    o.status = status_from_name(r[2 + nv + nr + 2]).value_or(Status::kFailed);
    o.warnings = static_cast<int>(std::strtol(r[2 + nv + nr + 3].c_str(), nullptr, 10));
    o.wall_seconds = std::strtod(r[2 + nv + nr + 4].c_str(), nullptr);
    o.message = r[2 + nv + nr + 5];
    cache_.try_emplace(x, o);
  }

  // The derivatives of earlier designs (exact gradients), by design.
  if (exact_gradients()) {
    CsvRow columns;
    for (const DesignVariable& v : variables_) columns.push_back(v.name);
    for (const ResponseSpec& r : study_.responses)
      for (const DesignVariable& v : variables_)
        columns.push_back("d " + r.name + " / d " + v.name);
    std::vector<CsvRow> rows;
    if (const int status =
            open_exit_status(derivatives_.open(settings_.output / "derivatives.csv", columns,
                                               settings_.resume, &rows, &error),
                             error))
      return status;
    for (const CsvRow& r : rows) {
      Design x;
      for (size_t i = 0; i < nv; ++i) x.push_back(std::strtod(r[i].c_str(), nullptr));
      auto jacobian = std::make_shared<Eigen::MatrixXd>(nr, nv);
      for (size_t k = 0; k < nr; ++k)
        for (size_t j = 0; j < nv; ++j)
          (*jacobian)(k, j) = std::strtod(r[nv + k * nv + j].c_str(), nullptr);
      jacobians_.try_emplace(x, std::move(jacobian));
    }
  }

  const std::vector<Design> points = start_points();
  // Designs evaluated at once: the starts, the central-difference points of one gradient, or
  // the variables whose derivatives one design's sensitivities compute in parallel.
  const long n_variables = static_cast<long>(variables_.size());
  const long at_once =
      std::max(static_cast<long>(points.size()), !needs_gradient(plan_.algorithm) ? 1
                                                 : exact_gradients()              ? n_variables
                                                                     : 2 * n_variables + 1);
  threads_ = batch_threads(settings_, at_once);
  omp_set_num_threads(threads_);  // the sensitivities' parallel loops (one thread inside a start)
  budget_total_ = static_cast<long>(plan_.max_evaluations) * static_cast<long>(points.size());
  progress_.set_total(budget_total_);
  std::vector<Start> starts(points.size());
  for (size_t s = 0; s < points.size(); ++s)
    starts[s].self = this, starts[s].index = static_cast<int>(s) + 1;
  // The constraints' scales: given, or |bound|, or for a bound of 0 the response's magnitude at
  // the first start's design (evaluated now; the start finds it done).
  const std::optional<std::vector<DesignOutcome>> first =
      points.empty() ? std::nullopt : outcomes(starts[0], {points[0]}, false, exact_gradients());
  for (const Constraint& c : plan_.constraints) {
    double scale = std::abs(c.bound);
    if (c.scale) {
      scale = *c.scale;
    } else if (c.bound == 0.0) {
      const double r = first ? std::abs((*first)[0].responses[c.response]) : 0.0;
      scale = std::isfinite(r) && r > 0.0 ? r : 1.0;
    }
    constraint_scales_.push_back(scale);
  }
  const int n_starts = static_cast<int>(points.size());
#pragma omp parallel for schedule(dynamic, 1) if (n_starts > 1) \
    num_threads(std::min(threads_, n_starts))
  for (int s = 0; s < n_starts; ++s) run_start(starts[s], points[s]);

  progress_.finish();
  bool written = history_.finalize({0, 1}, &error);
  if (written && exact_gradients()) {
    std::vector<int> keys;
    for (size_t i = 0; i < nv; ++i) keys.push_back(static_cast<int>(i));
    written = derivatives_.finalize(keys, &error);
  }
  // The best feasible design; ties go to the earliest (start, evaluation).
  const Record* best = nullptr;
  std::sort(records_.begin(), records_.end(), [](const Record& a, const Record& b) {
    return std::tie(a.start, a.evaluation) < std::tie(b.start, b.evaluation);
  });
  for (const Record& r : records_)
    if (r.feasible && (!best || r.objective < best->objective)) best = &r;
  return report(
      best, starts,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count(),
      written ? "" : error);
}

}  // namespace

int run_optimize(const Study& study, const RunSettings& settings) {
  Optimization o(study, settings);
  return o.run();
}

}  // namespace beamrail
