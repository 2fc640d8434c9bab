#include "optimizer/batch/start_runner.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>

#include "core/analysis/stop_request.hpp"
#include "optimizer/study/nlopt_setup.hpp"

namespace beamrail {

void EvaluationCost::add(const EvaluationCost& other) {
  simulated += other.simulated;
  failures += other.failures;
  exact_gradients += other.exact_gradients;
  gradient_fallbacks += other.gradient_fallbacks;
  if (fallback_reason.empty()) fallback_reason = other.fallback_reason;
  for (const std::string& w : other.sensitivity_warnings)
    if (sensitivity_warnings.size() < 20) sensitivity_warnings.insert(w);
}

std::optional<DesignOutcome> DesignCache::find(const Design& x) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = outcomes_.find(x);
  if (it == outcomes_.end()) return std::nullopt;
  return it->second;
}

void DesignCache::add(const Design& x, const DesignOutcome& o) {
  std::lock_guard<std::mutex> lock(mutex_);
  outcomes_.try_emplace(x, o);
}

bool DesignCache::find_jacobian(const Design& x,
                                std::shared_ptr<const Eigen::MatrixXd>* jacobian) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = jacobians_.find(x);
  if (it == jacobians_.end()) return false;
  *jacobian = it->second;
  return true;
}

void DesignCache::set_jacobian(const Design& x, std::shared_ptr<const Eigen::MatrixXd> jacobian) {
  std::lock_guard<std::mutex> lock(mutex_);
  jacobians_[x] = std::move(jacobian);
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Records what evaluating x with its sensitivities gave: the derivatives (to the cache and the
// sink) or why there are none.
void record_derivatives(const Design& x, const DesignOutcome& o, ResponseSensitivities& s,
                        DesignCache& cache, StartSink& sink, EvaluationCost& cost) {
  if (s.ok) {
    ++cost.exact_gradients;
    sink.derivatives(x, s.jacobian);
    cache.set_jacobian(x, std::make_shared<const Eigen::MatrixXd>(std::move(s.jacobian)));
    for (std::string& w : s.warnings)
      if (cost.sensitivity_warnings.size() < 20) cost.sensitivity_warnings.insert(std::move(w));
  } else {
    cache.set_jacobian(x, nullptr);
    if (o.status != Status::kOk) return;  // a failed design is a penalty: no gradient needed
    ++cost.gradient_fallbacks;
    if (cost.fallback_reason.empty()) cost.fallback_reason = s.message;
  }
}

class StartRun {
 public:
  StartRun(const OptimizationProblem& problem, const DesignEvaluator& evaluator,
           const StartTask& task, DesignCache& cache, int threads, StartSink& sink,
           const std::atomic<bool>& cancel, BatchExecutor* designs)
      : problem_(problem),
        plan_(problem.plan()),
        variables_(problem.variables()),
        evaluator_(evaluator),
        task_(task),
        cache_(cache),
        threads_(std::max(1, threads)),
        sink_(sink),
        cancel_(cancel),
        designs_(designs) {
    result_.index = task.index;
  }

  StartResult run();

 private:
  struct ConstraintRef {
    StartRun* self;
    int j;
  };

  bool must_stop() const { return stop_requested() || cancel_; }

  // The outcomes of designs xs, evaluated in parallel where new, recorded in order. A call is
  // evaluated whole or not at all: nullopt (nothing evaluated, NLopt told to stop) when the designs
  // new to the start would take it beyond its budget of max_evaluations designs. With
  // `sensitivities`, new designs are evaluated with their exact derivatives.
  std::optional<std::vector<DesignOutcome>> outcomes(const std::vector<Design>& xs, bool parallel,
                                                     bool sensitivities);
  // The outcome of x with the derivatives of its responses (null when it has none); nullopt
  // beyond the start's design budget.
  std::optional<std::pair<DesignOutcome, std::shared_ptr<const Eigen::MatrixXd>>> with_derivatives(
      const Design& x);
  // Value and (when grad != nullptr) gradient of value_of(outcome, which) at x: exact (the design
  // sensitivities) or by differences inside the bounds (central, or second-order one-sided at a
  // bound).
  double value_and_gradient(const double* x, double* grad, int which);
  // NLopt's view: scaled variables s in [0, 1]^n and the value divided by `scale`; gradient by
  // the chain rule.
  double scaled_value(const double* s, double* grad, double scale, int which);
  static double objective_callback(unsigned n, const double* x, double* grad, void* data);
  static double constraint_callback(unsigned n, const double* x, double* grad, void* data);

  const OptimizationProblem& problem_;
  const OptimizePlan& plan_;
  const std::vector<DesignVariable>& variables_;
  const DesignEvaluator& evaluator_;
  const StartTask& task_;
  DesignCache& cache_;
  int threads_;
  StartSink& sink_;
  const std::atomic<bool>& cancel_;
  BatchExecutor* designs_;  // null: the start's threads evaluate its designs
  // Distinct designs of this start -> evaluation number: its rows of history.csv, what its design
  // budget (max_evaluations) counts.
  std::map<Design, int> numbers_;
  nlopt_opt opt_ = nullptr;  // while it runs
  StartResult result_;
};

std::optional<std::vector<DesignOutcome>> StartRun::outcomes(const std::vector<Design>& xs,
                                                             bool parallel, bool sensitivities) {
  // The start's design budget: every design new to the start counts, simulated now or taken from
  // the cache (another start's, or history.csv's on --resume), so that a resumed run stops where
  // the uninterrupted one did. A call that does not fit is not evaluated at all.
  std::set<Design> fresh;
  for (const Design& x : xs)
    if (!numbers_.count(x)) fresh.insert(x);
  if (numbers_.size() + fresh.size() > static_cast<size_t>(plan_.max_evaluations)) {
    if (!result_.budget_spent) {
      result_.budget_spent = true;
      result_.budget_needed = static_cast<long>(fresh.size());
    }
    if (opt_) nlopt_force_stop(opt_);
    return std::nullopt;
  }
  std::vector<DesignOutcome> out(xs.size());
  std::vector<ResponseSensitivities> derivatives(sensitivities ? xs.size() : 0);
  std::vector<char> known(xs.size(), 0);
  std::vector<int> numbers(xs.size());
  // A design twice in xs is evaluated once: copy_of[i] is the index of its first occurrence.
  std::vector<long> copy_of(xs.size(), -1);
  std::map<Design, long> first;
  for (size_t i = 0; i < xs.size(); ++i) {
    auto [it, is_new] = numbers_.try_emplace(xs[i], static_cast<int>(numbers_.size()) + 1);
    numbers[i] = is_new ? it->second : -it->second;  // negative: this start has its row already
    const auto [f, first_time] = first.try_emplace(xs[i], static_cast<long>(i));
    if (!first_time) {
      copy_of[i] = f->second;
      known[i] = 1;
      continue;
    }
    if (const std::optional<DesignOutcome> c = cache_.find(xs[i])) {
      out[i] = *c;
      known[i] = 1;
    }
  }
  const long n = static_cast<long>(xs.size());
  const int threads = static_cast<int>(std::min<long>(threads_, n));
  EvaluationCost cost;  // of this call's designs, under the critical section below
  if (designs_ && parallel && !sensitivities) {
    // The new designs go to the executor (the ranks of an MPI job) and come back in any order.
    std::vector<long> at;
    std::vector<Design> batch;
    for (long i = 0; i < n; ++i)
      if (!known[i]) at.push_back(i), batch.push_back(xs[i]);
    std::vector<char> got(at.size(), 0);
    if (!batch.empty() && !must_stop())
      designs_->evaluate(evaluator_, batch, [&](long k, const DesignOutcome& o) {
        out[at[k]] = o;
        got[k] = 1;
        if (o.status != Status::kInterrupted) {
          ++cost.simulated;
          if (o.status != Status::kOk) ++cost.failures;
        }
        return !must_stop();
      });
    for (size_t k = 0; k < at.size(); ++k)
      if (!got[k]) {  // not started: a stop
        out[at[k]].status = Status::kInterrupted;
        out[at[k]].responses.assign(problem_.study().responses.size(), kNaN);
      }
  } else {
#pragma omp parallel for schedule(dynamic, 1) if (parallel && n > 1) num_threads(threads)
    for (long i = 0; i < n; ++i)
      if (!known[i]) {
        if (must_stop()) {
          out[i].status = Status::kInterrupted;  // not evaluated
          out[i].responses.assign(problem_.study().responses.size(), kNaN);
          continue;
        }
        out[i] = evaluator_.evaluate(xs[i], sensitivities ? &derivatives[i] : nullptr);
        if (out[i].status == Status::kInterrupted) continue;
#pragma omp critical(beamrail_start_cost)
        {
          ++cost.simulated;
          if (out[i].status != Status::kOk) ++cost.failures;
        }
      }
  }
  for (size_t i = 0; i < xs.size(); ++i)
    if (copy_of[i] >= 0) out[i] = out[copy_of[i]];
  for (size_t i = 0; i < xs.size(); ++i) {
    // An interrupted design is no result: neither cached nor in the history (a resumed run
    // evaluates it).
    if (out[i].status == Status::kInterrupted) continue;
    if (copy_of[i] < 0) cache_.add(xs[i], out[i]);
    if (sensitivities && !known[i])
      record_derivatives(xs[i], out[i], derivatives[i], cache_, sink_, cost);
    if (numbers[i] < 0) continue;
    sink_.record(OptimizationRecord{task_.index, numbers[i], xs[i], out[i],
                                    problem_.objective_of(out[i]), problem_.feasible(out[i])});
  }
  result_.cost.add(cost);
  return out;
}

std::optional<std::pair<DesignOutcome, std::shared_ptr<const Eigen::MatrixXd>>>
StartRun::with_derivatives(const Design& x) {
  const auto o = outcomes({x}, false, true);
  if (!o) return std::nullopt;
  std::shared_ptr<const Eigen::MatrixXd> jacobian;
  if (cache_.find_jacobian(x, &jacobian)) return std::make_pair((*o)[0], jacobian);
  // Evaluated before without its derivatives (a difference point, or history.csv on --resume):
  // once more, with them; no new row.
  if ((*o)[0].status == Status::kInterrupted || must_stop())
    return std::make_pair((*o)[0], nullptr);
  ResponseSensitivities s;
  const DesignOutcome again = evaluator_.evaluate(x, &s);
  if (again.status == Status::kInterrupted) return std::make_pair((*o)[0], nullptr);
  ++result_.cost.simulated;
  record_derivatives(x, again, s, cache_, sink_, result_.cost);
  cache_.find_jacobian(x, &jacobian);
  return std::make_pair((*o)[0], jacobian);
}

double StartRun::value_and_gradient(const double* x, double* grad, int which) {
  const size_t n = variables_.size();
  const Design x0(x, x + n);
  if (grad && plan_.gradient == OptimizePlan::Gradient::kExact) {
    const auto r = with_derivatives(x0);
    if (!r) {  // beyond the start's design budget: nothing evaluated, NLopt stops
      std::fill(grad, grad + n, 0.0);
      return kPenalty;
    }
    const double value = problem_.value_of(r->first, which);
    Eigen::VectorXd d;
    if (value >= kPenalty || !problem_.partials_of(r->first, which, d)) {
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
  const std::optional<std::vector<DesignOutcome>> evaluated = outcomes(points, true, false);
  if (!evaluated) {  // beyond the start's design budget: nothing evaluated, NLopt stops
    if (grad) std::fill(grad, grad + n, 0.0);
    return kPenalty;
  }
  const std::vector<DesignOutcome>& o = *evaluated;
  const double value = problem_.value_of(o[0], which);
  if (grad)
    for (size_t i = 0; i < n; ++i) {
      const double fa = problem_.value_of(o[1 + 2 * i], which),
                   fb = problem_.value_of(o[2 + 2 * i], which);
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

double StartRun::scaled_value(const double* s, double* grad, double scale, int which) {
  const size_t n = variables_.size();
  Design x(n);
  for (size_t i = 0; i < n; ++i) x[i] = physical_variable(variables_[i], s[i]);
  std::vector<double> gx(n, 0.0);
  const double v = value_and_gradient(x.data(), grad ? gx.data() : nullptr, which);
  if (grad)
    for (size_t i = 0; i < n; ++i)
      grad[i] = gx[i] * (variables_[i].upper - variables_[i].lower) / scale;
  return v >= kPenalty ? v : v / scale;
}

double StartRun::objective_callback(unsigned, const double* x, double* grad, void* data) {
  auto* self = static_cast<StartRun*>(data);
  try {
    ++self->result_.nlopt_evaluations;
    const double v = self->scaled_value(x, grad, self->result_.objective_scale, -1);
    if (self->must_stop()) {
      self->result_.stopped = true;
      nlopt_force_stop(self->opt_);
    }
    return v;
  } catch (...) {
    return kPenalty;  // never throw through NLopt
  }
}

double StartRun::constraint_callback(unsigned, const double* x, double* grad, void* data) {
  auto* ref = static_cast<ConstraintRef*>(data);
  try {
    StartRun& self = *ref->self;
    const int j = ref->j;
    // constraint_of is relative to |bound| (or 1): NLopt sees it relative to the constraint's
    // scale.
    const Constraint& c = self.plan_.constraints[j];
    const double relative_to = c.bound != 0.0 ? std::abs(c.bound) : 1.0;
    return self.scaled_value(x, grad, self.task_.constraint_scales.at(j) / relative_to, j);
  } catch (...) {
    return kPenalty;
  }
}

StartResult StartRun::run() {
  const NloptSetup setup(plan_, variables_);
  nlopt_opt opt = setup.get();
  nlopt_set_min_objective(opt, objective_callback, this);
  std::vector<ConstraintRef> refs;
  for (size_t j = 0; j < plan_.constraints.size(); ++j)
    refs.push_back(ConstraintRef{this, static_cast<int>(j)});
  for (ConstraintRef& ref : refs)
    nlopt_add_inequality_constraint(opt, constraint_callback, &ref, 1e-8);
  // The design budget (max_evaluations designs per start) is enforced in outcomes(); NLopt's own
  // limit on its calls is the same number, which stops a start whose calls keep returning to
  // designs it has evaluated (they cost no budget). Without gradients a call is one design: the
  // two limits coincide.
  nlopt_set_maxeval(opt, plan_.max_evaluations);
  if (plan_.max_seconds > 0) nlopt_set_maxtime(opt, plan_.max_seconds);
  nlopt_srand(plan_.seed + static_cast<unsigned long>(task_.index));  // stochastic algorithms

  // The objective's scale: its magnitude at the start point (constraints are already relative to
  // their bounds).
  const Design& x0 = task_.x0;
  const std::optional<std::vector<DesignOutcome>> o0 =
      outcomes({x0}, false, problem_.exact_gradients());
  const double f0 = o0 ? problem_.objective_of((*o0)[0]) : kPenalty;
  result_.objective_scale =
      plan_.objective_scale.value_or(f0 < kPenalty && std::abs(f0) > 0.0 ? std::abs(f0) : 1.0);
  Design x(x0.size());
  for (size_t i = 0; i < x0.size(); ++i) x[i] = scaled_variable(variables_[i], x0[i]);
  double f = 0.0;
  opt_ = opt;
  result_.result = nlopt_optimize(opt, x.data(), &f);
  if (result_.result < 0 && nlopt_get_errmsg(opt)) result_.message = nlopt_get_errmsg(opt);
  opt_ = nullptr;
  // Spending the design budget is a normal stop (NLopt returns FORCED_STOP, or whatever it made of
  // the penalty values it got after the stop): reported as NLopt reports its own limit.
  if (result_.budget_spent && !result_.stopped) result_.result = NLOPT_MAXEVAL_REACHED;
  // A start stopped before NLopt's first call (a stop request) was stopped by beamrail too.
  if (result_.result == NLOPT_FORCED_STOP && must_stop()) result_.stopped = true;
  result_.designs = static_cast<long>(numbers_.size());
  return result_;
}

}  // namespace

StartResult run_start(const OptimizationProblem& problem, const DesignEvaluator& evaluator,
                      const StartTask& task, DesignCache& cache, int threads, StartSink& sink,
                      const std::atomic<bool>& cancel, BatchExecutor* designs) {
  try {
    StartRun run(problem, evaluator, task, cache, threads, sink, cancel, designs);
    return run.run();
  } catch (const std::exception& e) {
    StartResult r;
    r.index = task.index;
    r.result = NLOPT_FAILURE;
    r.message = std::string("the start threw: ") + e.what();
    return r;
  } catch (...) {
    StartResult r;
    r.index = task.index;
    r.result = NLOPT_FAILURE;
    r.message = std::string("the start threw: ") + kUnknownException;
    return r;
  }
}

DesignOutcome evaluate_into_cache(const OptimizationProblem& problem,
                                  const DesignEvaluator& evaluator, const Design& x,
                                  DesignCache& cache, StartSink& sink, EvaluationCost* cost) {
  if (std::optional<DesignOutcome> known = cache.find(x)) return *known;
  const bool sensitivities = problem.exact_gradients();
  ResponseSensitivities s;
  DesignOutcome o = evaluator.evaluate(x, sensitivities ? &s : nullptr);
  if (o.status == Status::kInterrupted) return o;
  ++cost->simulated;
  if (o.status != Status::kOk) ++cost->failures;
  cache.add(x, o);
  if (sensitivities) record_derivatives(x, o, s, cache, sink, *cost);
  return o;
}

}  // namespace beamrail
