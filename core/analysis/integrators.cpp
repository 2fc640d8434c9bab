#include "core/analysis/integrators.hpp"

#include <arkode/arkode_arkstep.h>
#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <cvode/cvode_proj.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "core/analysis/auto_integrator.hpp"
#include "core/analysis/explicit_stability.hpp"
#include "core/analysis/klu_solver.hpp"
#include "core/analysis/modal_integrator.hpp"

namespace beamrail {
namespace {

// A state that is not finite after an accepted step (an error test passed by NaN): our own flag.
constexpr int kNonFiniteState = -1000;
// The flag of a call that reported the output time reached while the integrator's own time stayed
// short of it: its step had shrunk to nothing (to zero) and SUNDIALS took a zero step for one
// past the output, interpolating the output from it.
constexpr int kStepVanished = -1001;

// The symbolic name of a CVODE or ARKODE return flag ("CV_TOO_MUCH_WORK"); SUNDIALS allocates it.
std::string flag_name(char* (*get)(long int), int flag) {
  char* name = get(flag);
  std::string out = name ? name : "";
  std::free(name);
  return out;
}

// Words for a return flag of CVODE or ARKODE (`name` without its "CV_" / "ARK_" prefix) and what
// to do about it.
std::string flag_meaning(const std::string& name, long max_steps) {
  if (name == "TOO_MUCH_WORK")
    return "too much work: the run used up its step budget (max_steps = " +
           std::to_string(max_steps) +
           " over the whole run); raise max_steps, loosen rtol/atol, lengthen output_step (a step "
           "ends on every output row where the steps would be longer), or choose a method suited "
           "to the problem (a stiff structure needs bdf, dirk or modal)";
  if (name == "TOO_MUCH_ACC")
    return "the tolerances cannot be met at the precision of the arithmetic: loosen rtol/atol";
  if (name == "ERR_FAILURE")
    return "the error test failed repeatedly, also at the smallest step: the motion may jump or "
           "diverge; check the loads, or loosen rtol/atol";
  if (name == "CONV_FAILURE")
    return "the Newton iteration failed to converge repeatedly, also at the smallest step: the "
           "motion may diverge; check the loads, or use \"jacobian\": \"exact\"";
  if (name == "LINIT_FAIL" || name == "LSETUP_FAIL" || name == "LSOLVE_FAIL")
    return "the linear solver failed (a singular Newton matrix): check the scene for bodies "
           "without mass or inertia";
  if (name == "RHSFUNC_FAIL" || name == "FIRST_RHSFUNC_ERR" || name == "REPTD_RHSFUNC_ERR" ||
      name == "UNREC_RHSFUNC_ERR")
    return "the forces became non-finite and smaller steps did not help: the motion diverged; "
           "check the loads, the masses and the stiffnesses";
  if (name == "ILL_INPUT")
    return "the integrator refused its input: check t_end, output_step, max_step and "
           "initial_step (too small for the arithmetic, or inconsistent)";
  if (name == "TOO_CLOSE") return "t_end or output_step is too small to start the integration";
  if (name == "MEM_FAIL") return "out of memory";
  return "the integrator failed";
}

// The reason a run ended: the budget, a stop request, the model's side, or the integrator's flag
// in words, with SUNDIALS' name of the flag and its own last message.
std::string explain(int flag, const std::string& package, const std::string& name,
                    const std::string& module_message, const OdeContext& context, long max_steps) {
  if (context.interrupted) return "interrupted";
  if (context.timed_out) return "timeout: the run exceeded its max_seconds budget";
  if (!context.callback_error.empty())
    return "error while evaluating the model: " + context.callback_error;
  if (!context.divergence.empty()) return context.divergence;
  if (flag == kNonFiniteState)
    return "the state became non-finite: the motion diverged; check the loads, the masses and "
           "the stiffnesses";
  if (flag == kStepVanished)
    return context.out_of_range.empty()
               ? "the step size fell to zero before the output time: the tolerances cannot be "
                 "met there, or the motion jumps; loosen rtol/atol or check the loads"
               : context.out_of_range +
                     " (the integrator could not step past it: its step fell to zero)";
  const size_t underscore = name.find('_');
  const std::string bare = underscore == std::string::npos ? name : name.substr(underscore + 1);
  // Repeated right-hand-side or Newton failures over states outside the element laws' range.
  if (!context.out_of_range.empty() && (bare.find("RHSFUNC") != std::string::npos ||
                                        bare == "CONV_FAILURE" || bare == "ERR_FAILURE"))
    return context.out_of_range + " (the integrator could not step past it: " + package + " " +
           name + ")";
  std::string why = flag_meaning(bare, max_steps) + " (" + package + " " +
                    (name.empty() ? "flag" : name) + ", " + std::to_string(flag) + ")";
  if (!module_message.empty()) why += " [" + module_message + "]";
  return why;
}

// Whether every entry of y is finite.
bool finite(N_Vector y) {
  const double* a = N_VGetArrayPointer(y);
  const long n = N_VGetLength(y);
  for (long i = 0; i < n; ++i)
    if (!std::isfinite(a[i])) return false;
  return true;
}

SolverStats& operator+=(SolverStats& a, const SolverStats& b) {
  a.steps += b.steps;
  a.rhs_evaluations += b.rhs_evaluations;
  a.jacobian_evaluations += b.jacobian_evaluations;
  a.nonlinear_iterations += b.nonlinear_iterations;
  a.nonlinear_failures += b.nonlinear_failures;
  a.error_test_failures += b.error_test_failures;
  return a;
}

// The Newton iteration's convergence coefficient of the implicit Runge-Kutta methods on scenes
// with damping (ARKODE's default 0.1; ArkodeImplicit::init): kDampedNewtonCoefficient, but not
// below kDampedNewtonFloor / rtol of the states, near which the iteration meets the rounding of
// the stiff forces and fails to converge (a flexible pendulum with beam damping 1e-4 at rtol
// 1e-8 ran past 60 s where 0.1 took 3.4 s, and takes 6.1 s with the floor; an adversarial
// review). 1e-3, not 1e-4 (2026-12-01, docs/transient_measurements.md "dirk's Newton
// coefficient on damped scenes"): at 1e-4 three iterations often fell short of it, and the
// stiff-hinge pendulum with a damped axle failed 25,290 Newton iterations in 16,530 steps at
// rtol 1e-6 (1.26 s; now 3,574 in 6,066, 0.34 s), as accurate; the damped beams that asked for
// a tight coefficient stay within 0.004 rtol now that the steps end on the outputs.
constexpr double kDampedNewtonCoefficient = 1e-3;
constexpr double kDampedNewtonFloor = 1e-10;
// Newton iterations per stage on those scenes (ARKODE's default 3). A coefficient a hundred times
// ARKODE's asks for more than three modified-Newton iterations where the rate is slow, and each
// shortfall cost a failure, a new Jacobian and the stage again: the failures were the retries,
// not a wrong Jacobian (re-formed at every step, or by differences, they failed as often).
// Measured (2026-12-01, docs/transient_measurements.md "Five Newton iterations on damped
// scenes"): a flexible pendulum with a damped axle and rod at rtol 1e-6 9,434 failures in 9,140
// steps, 1.28 s, with five iterations 206 and 0.53 s; a carriage spinning on a damped rail 1,243
// in 1,318, 0.053 -> 0.036 s; errors as before. Undamped scenes keep three (five there cost 5 to
// 20 % and failed little).
constexpr int kDampedNewtonIterations = 5;

// The error test failures in a row after which an implicit Runge-Kutta step fails (ARKODE's
// default 7). A mode that damping makes overdamped and very stiff (a 3 kg point-mass tip of rotary
// inertia 1e-6 on a 1 m cantilever of 40 mm steel with beam damping 1e-3 s: a decay rate near
// d w^2 = 1.6e8 1/s) needs, after a load's jump, steps near its time constant before the
// embedded estimate passes, and each failure past the second cuts the step to 0.3 of it or
// less: from 1e-4 s to 6e-9 s up to 10 failures. At 7 every table but ARK437 failed there
// ("the error test failed repeatedly, also at the smallest step") at rtol 1e-4, 1e-6 and 1e-8;
// of the nine runs of the default table, ESDIRK547 and SDIRK 5-3-4 at 8 eight still failed, at
// 10 two (the default table at 1e-6, SDIRK 5-3-4 at 1e-4), at 12 none, with 0.014 to 0.45 times
// their tolerance against the modal method at rtol 1e-10 (rows then interpolated; 8.5e-5 to
// 0.036 since they are steps) (tests/core/analysis/integrators_test.cpp,
// ImplicitRungeKuttaStepsThroughAnOverdampedMode).
// Where 7 sufficed nothing changes: the limit only ends a step that would have failed. 25 leaves
// room for decay rates 1e7 times faster (0.3^15 = 1.4e-8).
constexpr int kDirkMaxErrorTestFailures = 25;

// What the SUNDIALS integrators share: max_steps over the whole run (SUNDIALS counts them per call
// and resets its counters when it restarts at a load's jump), statistics over the whole run, and a
// check of the state after each call.
constexpr const char* kFixedStepWarning =
    "fixed_step: every step has the given length and no error is estimated (rtol and atol only "
    "set the Newton tolerance); measure the error by halving the step";

class SundialsIntegrator : public Integrator {
 public:
  int advance(double tout, double tstop, N_Vector y, double* t) final {
    const long left = max_steps_ - stats().steps;
    if (left <= 0) return -1;  // *_TOO_MUCH_WORK
    context_->nonfinite_evaluations = 0;
    context_->out_of_range.clear();
    const int flag = evolve(tout, tstop, y, t, left);
    if (flag >= 0 && !finite(y)) return kNonFiniteState;
    // Reached by a step of zero length: a dirk run whose trial states left a rail's travel
    // shrank its step to 0 at the edge and then reported every output reached, the carriage
    // frozen there, ok (an adversarial review: 0.21 m off). The run ends where it stood.
    if (const double now = current_time();
        flag >= 0 && now < *t - 1e-12 * std::max(1.0, std::abs(*t))) {
      *t = now;
      return kStepVanished;
    }
    return flag;
  }
  void restart(double t, N_Vector y) final {
    before_ += segment_stats();
    reinit(t, y);
  }
  SolverStats stats() const final {
    SolverStats s = before_;
    s += segment_stats();
    return s;
  }
  std::string failure(int flag) const final {
    std::string why =
        explain(flag, package_,
                flag < 0 && flag != kNonFiniteState && flag != kStepVanished ? name(flag) : "",
                messages_.last, *context_, run_max_steps_);
    if (fixed_step_ && !context_->interrupted && !context_->timed_out)
      why += flag == -1  // *_TOO_MUCH_WORK
                 ? "; with fixed_step every step is taken: a longer fixed_step or a larger "
                   "max_steps"
                 : "; with fixed_step the step cannot shrink: try a shorter fixed_step, or a "
                   "looser rtol (the Newton tolerance)";
    return why;
  }

 protected:
  // Where a step ends so that the output at tout is a step of the run, not SUNDIALS' dense output
  // between steps, whose error no tolerance controls: the steps grow far past the output spacing
  // where the motion is slow. A 3 kg point-mass tip on a 1 m cantilever of 10 mm steel with beam
  // damping 1e-2 s under a step of (0, -1, 0.3) N, 0.2 s, outputs every 1 ms: dirk's default
  // table took 19 / 27 / 48 steps at rtol 1e-4 / 1e-6 / 1e-8 and its interpolated outputs came
  // out 3.8 / 18 / 17 rtol of the motion off against the modal method at rtol 1e-10, silent (a
  // lower interpolant degree was worse); ending its steps on the outputs, 208 / 210 / 216 steps
  // and 4e-9 / 4e-7 / 3e-5; bdf at rtol 1e-4 / 1e-6 0.67 / 1.3, and 1.8e-5 / 0.0029 so
  // (tests/core/analysis/integrators_test.cpp, OutputsAreStepsNotInterpolants). A fixed step
  // keeps its length.
  double output_stop(double tout, double tstop) const {
    return fixed_step_ ? tstop : std::min(tout, tstop);
  }
  // Integrates to tout (not past tstop) taking at most max_steps steps.
  virtual int evolve(double tout, double tstop, N_Vector y, double* t, long max_steps) = 0;
  // The time of the integrator's last step (its outputs are interpolated at or before it).
  virtual double current_time() const = 0;
  virtual void reinit(double t, N_Vector y) = 0;
  // Counters since the last (re)initialization.
  virtual SolverStats segment_stats() const = 0;
  virtual std::string name(int flag) const = 0;

  bool fail(std::string* error, const std::string& what) {
    *error = what;
    return false;
  }

  void* mem_ = nullptr;
  OdeContext* context_ = nullptr;
  SundialsMessages messages_;
  long max_steps_ = 0;      // of this integrator (max_steps less the earlier phases' steps)
  long run_max_steps_ = 0;  // max_steps of the whole run
  std::string package_;
  bool fixed_step_ = false;

 private:
  SolverStats before_;  // up to the last restart
};

// Dense or sparse (KLU) matrix and solver for the implicit methods.
struct LinearAlgebra {
  MatrixOwner matrix;
  LinearSolverOwner solver;
  bool sparse = false;

  bool make(const IntegratorOptions& o, OdeContext& c, SUNContext ctx, N_Vector y,
            std::string* error) {
    const long n = c.model.n_states;
    sparse = o.linear_solver == LinearSolverKind::kSparse ||
             (o.linear_solver == LinearSolverKind::kAuto && n >= kSparseStateThreshold);
    if (sparse && o.jacobian == JacobianKind::kFiniteDifference) {
      *error = "finite-difference Jacobians need the dense linear solver";
      return false;
    }
    if (sparse) {
      // The topology's pattern and ordering, analysed once and shared through the cache.
      c.structure = c.structure_cache ? c.structure_cache->get(c.model)
                                      : std::make_shared<const SparseStructure>(c.model);
      matrix.m = SUNSparseMatrix(n, n, std::max(1L, c.structure->pattern().nnz()), CSC_MAT, ctx);
      solver.s = make_klu_solver(c.structure, ctx);
    } else {
      matrix.m = SUNDenseMatrix(n, n, ctx);
      solver.s = SUNLinSol_Dense(y, matrix.m, ctx);
    }
    if (!matrix.m || !solver.s) {
      *error = "could not create the linear solver";
      return false;
    }
    return true;
  }
  template <class SetJac>
  void jacobian(const IntegratorOptions& o, SetJac&& set) const {
    if (sparse)
      set(ode_sparse_jacobian);
    else if (o.jacobian == JacobianKind::kExact)
      set(ode_dense_jacobian);
  }
};

class Cvode : public SundialsIntegrator {
 public:
  bool init(const IntegratorOptions& o, OdeContext& c, SUNContext ctx, N_Vector y0,
            std::string* error) {
    context_ = &c;
    package_ = "CVODE";
    max_steps_ = std::max(1L, o.max_steps - o.steps_before);
    run_max_steps_ = o.max_steps;
    mem_ = CVodeCreate(o.method == IntegratorMethod::kAdams ? CV_ADAMS : CV_BDF, ctx);
    if (!mem_) return fail(error, "could not create CVODE");
    CVodeSetErrHandlerFn(mem_, &SundialsMessages::handler, &messages_);
    rtol_ = o.rtol;
    atol_ = o.atol;
    if (CVodeInit(mem_, ode_rhs, 0.0, y0) < 0 || CVodeWFtolerances(mem_, ode_error_weights) < 0 ||
        CVodeSetUserData(mem_, &c) < 0)
      return fail(error, "CVODE set-up failed: " + messages_.last);
    if (!algebra_.make(o, c, ctx, y0, error)) return false;
    if (CVodeSetLinearSolver(mem_, algebra_.solver.s, algebra_.matrix.m) < 0)
      return fail(error, "CVODE linear solver: " + messages_.last);
    algebra_.jacobian(o, [&](CVLsJacFn f) { CVodeSetJacFn(mem_, f); });
    linear_solver = algebra_.sparse ? "sparse" : "dense";
    nnz = c.structure ? c.structure->pattern().nnz() : 0;
    // |q| = 1 by projection (CVODE projects for BDF only; Adams states are renormalized when
    // the analysis restarts and the rotation uses q/|q| throughout).
    if (o.method == IntegratorMethod::kBdf) CVodeSetProjFn(mem_, ode_project);
    CVodeSetMaxOrd(mem_,
                   o.method == IntegratorMethod::kAdams ? std::min(12, o.max_order) : o.max_order);
    if (o.stability_limit_detection && o.method == IntegratorMethod::kBdf)
      CVodeSetStabLimDet(mem_, SUNTRUE);
    if (o.max_step > 0.0) CVodeSetMaxStep(mem_, o.max_step);
    if (o.initial_step > 0.0) CVodeSetInitStep(mem_, o.initial_step);
    return true;
  }
  ~Cvode() override { CVodeFree(&mem_); }

 private:
  // CVODE's own weights for scalar tolerances (1 / (rtol |y_i| + atol), the same arithmetic), and
  // the state they are asked for shown to step_taken: CVODE asks at the start of each step for
  // the state its last step accepted (and at a start for the initial state), so every accepted
  // state is seen, with no change to the steps (in one-step mode a step ending on both the output
  // and the stop time would plan its successor differently).
  int weights(N_Vector y, N_Vector w) {
    const double* a = N_VGetArrayPointer(y);
    double* out = N_VGetArrayPointer(w);
    const long n = N_VGetLength(y);
    for (long i = 0; i < n; ++i) {
      const double scale = rtol_ * std::abs(a[i]) + atol_;
      if (scale <= 0.0) return -1;
      out[i] = 1.0 / scale;
    }
    if (context_->step_taken) context_->step_taken(current_time(), a);
    return 0;
  }
  int evolve(double tout, double tstop, N_Vector y, double* t, long max_steps) override {
    // The context may serve another CVODE integrator of the same run (auto's phases).
    context_->error_weights = [this](N_Vector y, N_Vector w) { return weights(y, w); };
    CVodeSetMaxNumSteps(mem_, max_steps);
    // A multistep method's step ends on the output only where the next step would be longer than
    // the spacing: each cut step perturbs its history. Ending every step on the outputs took bdf
    // on a free body spun up by a follower torque (rtol 1e-9, outputs every 0.05 s) from 14 to 54
    // rtol off (follower_load_test.cpp), and on the 40 mm tip under 1 kN with beam damping 1e-2 s
    // at rtol 1e-8 from 3.8 to 9.8 tolerances; ending them only so, 14 and 3.8. Where the steps
    // sit near the spacing the cuts still perturb it: that free body at rtol 1e-8 with outputs
    // every 0.02 s went from 10 to 40 tolerances (docs/transient_measurements.md "dirk's outputs
    // are steps").
    double now = 0.0, next_step = 0.0;
    CVodeGetCurrentTime(mem_, &now);
    CVodeGetCurrentStep(mem_, &next_step);
    CVodeSetStopTime(mem_, now < tout && next_step > tout - *t ? output_stop(tout, tstop) : tstop);
    return CVode(mem_, tout, y, t, CV_NORMAL);
  }
  void reinit(double t, N_Vector y) override { CVodeReInit(mem_, t, y); }
  double rtol_ = 0.0, atol_ = 0.0;
  double current_time() const override {
    double now = 0.0;
    CVodeGetCurrentTime(mem_, &now);
    return now;
  }
  std::string name(int flag) const override { return flag_name(CVodeGetReturnFlagName, flag); }
  SolverStats segment_stats() const override {
    SolverStats s;
    long fd = 0;
    CVodeGetNumSteps(mem_, &s.steps);
    CVodeGetNumRhsEvals(mem_, &s.rhs_evaluations);
    CVodeGetNumLinRhsEvals(mem_, &fd);
    s.rhs_evaluations += fd;
    CVodeGetNumJacEvals(mem_, &s.jacobian_evaluations);
    CVodeGetNumNonlinSolvIters(mem_, &s.nonlinear_iterations);
    CVodeGetNumNonlinSolvConvFails(mem_, &s.nonlinear_failures);
    CVodeGetNumErrTestFails(mem_, &s.error_test_failures);
    return s;
  }

  LinearAlgebra algebra_;
};

// ARKODE table names are accepted with or without their "ARKODE_" prefix.
std::string table_name(const std::string& name) {
  return name.rfind("ARKODE_", 0) == 0 ? name : "ARKODE_" + name;
}

class ArkodeImplicit : public SundialsIntegrator {
 public:
  bool init(const IntegratorOptions& o, OdeContext& c, SUNContext ctx, N_Vector y0,
            std::string* error) {
    context_ = &c;
    package_ = "ARKODE";
    max_steps_ = std::max(1L, o.max_steps - o.steps_before);
    run_max_steps_ = o.max_steps;
    mem_ = ARKStepCreate(nullptr, ode_rhs, 0.0, y0, ctx);
    if (!mem_) return fail(error, "could not create ARKODE");
    ARKStepSetErrHandlerFn(mem_, &SundialsMessages::handler, &messages_);
    const std::string table = table_name(o.table.empty() ? kDefaultDirkTable : o.table);
    if (ARKStepSetTableName(mem_, table.c_str(), "ARKODE_ERK_NONE") < 0)
      return fail(error, "unknown or unusable implicit table \"" + o.table + "\"");
    if (ARKStepSStolerances(mem_, o.rtol, o.atol) < 0 || ARKStepSetUserData(mem_, &c) < 0)
      return fail(error, "ARKODE set-up failed: " + messages_.last);
    if (!algebra_.make(o, c, ctx, y0, error)) return false;
    if (ARKStepSetLinearSolver(mem_, algebra_.solver.s, algebra_.matrix.m) < 0)
      return fail(error, "ARKODE linear solver: " + messages_.last);
    algebra_.jacobian(o, [&](ARKLsJacFn f) { ARKStepSetJacFn(mem_, f); });
    linear_solver = algebra_.sparse ? "sparse" : "dense";
    nnz = c.structure ? c.structure->pattern().nnz() : 0;
    ARKStepSetPostprocessStepFn(mem_, ode_normalize);
    // The variable-order predictor: on the reference cantilever (N = 10, rtol 3e-6), together with
    // deducing each stage's derivative from its Newton solution, it cut right-hand sides from 99k
    // to 53k. The deduction is not taken (ARKODE evaluates each stage's derivative): it left runs
    // far off where a stiff mode rings against a slow motion, silent. A 3 kg point-mass tip
    // (rotary inertia 1e-6) on a 1 m cantilever of 10 mm steel under a 1 N step, 0.3 s, came out
    // 4.3 / 25 / 52 / 19 rtol of its motion off at rtol 1e-4 / 1e-5 / 1e-6 / 1e-7 with it and
    // 0.0026 / 0.014 / 0.025 / 0.083 without; a 10 m beam spun up by its hub to 6 rad/s over 2 s
    // (auto runs dirk) 32 / 87 / 3.3 error weights (rtol x 10 m) at rtol 1e-4 / 1e-5 / 1e-6 with
    // it, 0.05 / 0.22 / 0.13 without (integrators_test.cpp). Its cost where it was right: the
    // reference cantilever at rtol 1e-6 0.27 -> 0.29 s (27.6k -> 40.9k right-hand sides).
    ARKStepSetPredictorMethod(mem_, 2);
    ARKStepSetMaxErrTestFails(mem_, kDirkMaxErrorTestFailures);
    // An evaluated derivative carries the Newton iteration's error times the stiffness, which
    // damping makes large and real: the reference cantilever in 10 segments with beam damping
    // 1e-3 s (its fastest modes overdamped), 1 N step, 0.05 s, came out 109 / 120 rtol off at rtol
    // 1e-4 / 1e-6 (ESDIRK547 21 / 0.31), silent, at ARKODE's Newton coefficient 0.1, and 0.26 /
    // 0.33 (0.25 / 0.029) at kDampedNewtonCoefficient. Only for damped scenes: on an undamped
    // stiff joint (a cantilever on a body held by a fixed joint of compliance 1e-6) the tight
    // coefficient took 2.3 million steps at rtol 1e-8 against 75k.
    if (largest_damping(c.model) > 0.0) {
      ARKStepSetNonlinConvCoef(
          mem_, std::clamp(kDampedNewtonFloor / o.rtol, kDampedNewtonCoefficient, 0.1));
      ARKStepSetMaxNonlinIters(mem_, kDampedNewtonIterations);
    }
    if (o.max_step > 0.0) ARKStepSetMaxStep(mem_, o.max_step);
    if (o.initial_step > 0.0) ARKStepSetInitStep(mem_, o.initial_step);
    if (o.fixed_step > 0.0) {
      if (ARKStepSetFixedStep(mem_, o.fixed_step) < 0)
        return fail(error, "ARKODE refused fixed_step: " + messages_.last);
      warnings.push_back(kFixedStepWarning);
      fixed_step_ = true;
    }
    return true;
  }
  ~ArkodeImplicit() override { ARKStepFree(&mem_); }

 private:
  int evolve(double tout, double tstop, N_Vector y, double* t, long max_steps) override {
    ARKStepSetMaxNumSteps(mem_, max_steps);
    ARKStepSetStopTime(mem_, output_stop(tout, tstop));
    return ARKStepEvolve(mem_, tout, y, t, ARK_NORMAL);
  }
  void reinit(double t, N_Vector y) override { ARKStepReInit(mem_, nullptr, ode_rhs, t, y); }
  double current_time() const override {
    double now = 0.0;
    ARKStepGetCurrentTime(mem_, &now);
    return now;
  }
  std::string name(int flag) const override { return flag_name(ARKStepGetReturnFlagName, flag); }
  SolverStats segment_stats() const override {
    SolverStats s;
    long fe = 0, fi = 0, fd = 0;
    ARKStepGetNumSteps(mem_, &s.steps);
    ARKStepGetNumRhsEvals(mem_, &fe, &fi);
    ARKStepGetNumLinRhsEvals(mem_, &fd);
    s.rhs_evaluations = fe + fi + fd;
    ARKStepGetNumJacEvals(mem_, &s.jacobian_evaluations);
    ARKStepGetNumNonlinSolvIters(mem_, &s.nonlinear_iterations);
    ARKStepGetNumNonlinSolvConvFails(mem_, &s.nonlinear_failures);
    ARKStepGetNumErrTestFails(mem_, &s.error_test_failures);
    return s;
  }

  LinearAlgebra algebra_;
};

class ArkodeExplicit : public SundialsIntegrator {
 public:
  bool init(const IntegratorOptions& o, OdeContext& c, SUNContext ctx, N_Vector y0,
            std::string* error) {
    context_ = &c;
    package_ = "ARKODE";
    max_steps_ = std::max(1L, o.max_steps - o.steps_before);
    run_max_steps_ = o.max_steps;
    mem_ = ERKStepCreate(ode_rhs, 0.0, y0, ctx);
    if (!mem_) return fail(error, "could not create ARKODE");
    ERKStepSetErrHandlerFn(mem_, &SundialsMessages::handler, &messages_);
    const std::string table = table_name(o.table.empty() ? kDefaultErkTable : o.table);
    if (ERKStepSetTableName(mem_, table.c_str()) < 0)
      return fail(error, "unknown explicit table \"" + o.table + "\"");
    if (ERKStepSStolerances(mem_, o.rtol, o.atol) < 0 || ERKStepSetUserData(mem_, &c) < 0)
      return fail(error, "ARKODE set-up failed: " + messages_.last);
    ERKStepSetPostprocessStepFn(mem_, ode_normalize);
    double max_step = o.max_step;
    if (o.fixed_step <= 0.0) {
      // Not so far beyond the table's stability that its rows go wrong (explicit_longest_wh).
      const double fastest = fastest_mode(c.model, c.data, N_VGetArrayPointer(y0), 0.0);
      if (fastest > 0.0) {
        const double longest = explicit_longest_wh(o.rtol) / fastest;
        if (!(max_step > 0.0) || longest < max_step) max_step = longest;
      }
    }
    if (max_step > 0.0) ERKStepSetMaxStep(mem_, max_step);
    max_step_ = max_step;
    c.accepted_t = 0.0;  // ERKStepCreate's start
    if (o.initial_step > 0.0) ERKStepSetInitStep(mem_, o.initial_step);
    if (o.fixed_step > 0.0) {
      if (ERKStepSetFixedStep(mem_, o.fixed_step) < 0)
        return fail(error, "ARKODE refused fixed_step: " + messages_.last);
      warnings.push_back(kFixedStepWarning);
      fixed_step_ = true;
      // Nothing would notice modes that grow without bound: refused before the run.
      const FixedStepStability s =
          fixed_step_stability(c.model, c.data, N_VGetArrayPointer(y0), 0.0, table, o.fixed_step,
                               o.horizon > 0.0 ? o.horizon : o.fixed_step);
      if (!s.checked) {
        warnings.push_back(
            "fixed_step: the scene's fastest mode could not be computed; the explicit table's "
            "stability at this step is not checked");
      } else if (s.growth > kFixedStepMaxGrowth) {
        char text[400];
        std::snprintf(text, sizeof text,
                      "fixed_step %g s is beyond the stability of the explicit table %s: the "
                      "scene's fastest mode (%.4g rad/s at the start) would grow by a factor of "
                      "%.3g over the run; a fixed step of at most %.3g s keeps it within %g, or "
                      "use dirk",
                      o.fixed_step, table.c_str(), s.fastest, s.growth, s.stable_step,
                      kFixedStepMaxGrowth);
        return fail(error, text);
      }
    }
    return true;
  }
  ~ArkodeExplicit() override { ERKStepFree(&mem_); }

 private:
  // An explicit method cannot retry a step whose stage found an element outside its law's range:
  // it stopped there, at the first stage outside, which lies past where the element left (a
  // carriage thrown past its travel's end: 44 ms late of 0.055 s at rtol 1e-4), or is no exit at
  // all (a stage's state is not the motion's: at a grazing edge the run failed where the motion
  // stayed inside). So from the last accepted state it goes again with steps a quarter of the
  // way to that stage, up to kLocateRounds times, until the stage is within kLocated of it (the
  // run ends there) or the steps pass it (and go on at their own length).
  static constexpr int kLocateRounds = 40;
  static constexpr double kLocated = 1e-9;
  int evolve(double tout, double tstop, N_Vector y, double* t, long max_steps) override {
    const double stop = output_stop(tout, tstop);
    ERKStepSetMaxNumSteps(mem_, max_steps);
    ERKStepSetStopTime(mem_, stop);
    int flag = ERKStepEvolve(mem_, tout, y, t, ARK_NORMAL);
    for (int round = 0; round < kLocateRounds && flag == ARK_UNREC_RHSFUNC_ERR &&
                        !context_->out_of_range.empty() && context_->divergence.empty() &&
                        !fixed_step_ && !context_->should_stop();
         ++round) {
      const double from = context_->accepted_t;  // y: the state there (ARKODE's yn)
      const double gap = context_->out_of_range_t - from;
      if (!(gap > kLocated * std::max(1.0, std::abs(from)))) break;
      restart(from, y);
      context_->nonfinite_evaluations = 0;
      context_->out_of_range.clear();
      ERKStepSetMaxStep(mem_, 0.25 * gap);
      const double past = std::min(stop, from + 2.0 * gap);
      ERKStepSetStopTime(mem_, past);
      flag = ERKStepEvolve(mem_, past, y, t, ARK_NORMAL);
      if (flag >= 0 && *t < stop) {  // through: on at the steps' own length
        ERKStepSetMaxStep(mem_, max_step_);
        ERKStepSetStopTime(mem_, stop);
        flag = ERKStepEvolve(mem_, tout, y, t, ARK_NORMAL);
      }
    }
    return flag;
  }
  double max_step_ = 0.0;  // of the run: none when not positive
  void reinit(double t, N_Vector y) override {
    ERKStepReInit(mem_, ode_rhs, t, y);
    context_->accepted_t = t;
  }
  double current_time() const override {
    double now = 0.0;
    ERKStepGetCurrentTime(mem_, &now);
    return now;
  }
  std::string name(int flag) const override { return flag_name(ERKStepGetReturnFlagName, flag); }
  SolverStats segment_stats() const override {
    SolverStats s;
    ERKStepGetNumSteps(mem_, &s.steps);
    ERKStepGetNumRhsEvals(mem_, &s.rhs_evaluations);
    ERKStepGetNumErrTestFails(mem_, &s.error_test_failures);
    return s;
  }
};

template <class T>
std::unique_ptr<Integrator> build(const IntegratorOptions& o, OdeContext& c, SUNContext ctx,
                                  N_Vector y0, std::string* error) {
  auto integrator = std::make_unique<T>();
  if (!integrator->init(o, c, ctx, y0, error)) return nullptr;
  return integrator;
}

}  // namespace

std::unique_ptr<Integrator> make_integrator(const IntegratorOptions& options, OdeContext& context,
                                            SUNContext sunctx, N_Vector y0, std::string* error) {
  if (!options.IsValid(error)) return nullptr;
  switch (options.method) {
    case IntegratorMethod::kBdf:
    case IntegratorMethod::kAdams:
      return build<Cvode>(options, context, sunctx, y0, error);
    case IntegratorMethod::kDirk:
      return build<ArkodeImplicit>(options, context, sunctx, y0, error);
    case IntegratorMethod::kErk:
      return build<ArkodeExplicit>(options, context, sunctx, y0, error);
    case IntegratorMethod::kModal:
      return make_modal_integrator(options, context, y0, error);
    case IntegratorMethod::kAuto:
      return make_auto_integrator(options, context, sunctx, y0, error);
  }
  *error = "unknown integrator method";
  return nullptr;
}

}  // namespace beamrail
