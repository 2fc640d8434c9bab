#include "core/analysis/transient.hpp"

#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <cvode/cvode_proj.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>

#include "core/analysis/sundials_support.hpp"
#include "core/model/dynamics.hpp"
#include "core/model/forces.hpp"

namespace beamrail {
namespace {

struct OdeContext {
  const Model& model;
  Data& data;
  std::vector<Mat13> blocks;
  std::string callback_error;  // an exception caught inside a callback
};

// dy/dt; returns 1 (recoverable: CVODE retries with a smaller step) on non-finite values.
int rhs(double t, N_Vector y, N_Vector ydot, void* user) {
  auto* c = static_cast<OdeContext*>(user);
  try {
    const long n = c->model.n_states;
    double* f = N_VGetArrayPointer(ydot);
    state_derivative(c->model, c->data, t, N_VGetArrayPointer(y), f);
    for (long i = 0; i < n; ++i)
      if (!std::isfinite(f[i])) return 1;
    return 0;
  } catch (const std::exception& e) {
    c->callback_error = e.what();
  } catch (...) {
    c->callback_error = "unknown error in the right-hand side";
  }
  return -1;
}

int dense_jacobian(double t, N_Vector y, N_Vector, SUNMatrix jac, void* user, N_Vector, N_Vector,
                   N_Vector) {
  auto* c = static_cast<OdeContext*>(user);
  try {
    state_jacobian_blocks(c->model, c->data, t, N_VGetArrayPointer(y), c->blocks);
    scatter_dense(c->model, c->blocks, SUNDenseMatrix_Data(jac), SUNDenseMatrix_Rows(jac));
    const double* a = SUNDenseMatrix_Data(jac);
    const long n = static_cast<long>(c->model.n_states);
    for (long i = 0; i < n * n; ++i)
      if (!std::isfinite(a[i])) return 1;
    return 0;
  } catch (const std::exception& e) {
    c->callback_error = e.what();
  } catch (...) {
    c->callback_error = "unknown error in the Jacobian";
  }
  return -1;
}

// Projection onto |q| = 1 for every body: corr = q/|q| - q; the error estimate loses its
// component along q.
int project_quaternions(double, N_Vector ycur, N_Vector corr, double, N_Vector err, void* user) {
  auto* c = static_cast<OdeContext*>(user);
  const double* y = N_VGetArrayPointer(ycur);
  double* dy = N_VGetArrayPointer(corr);
  double* e = err ? N_VGetArrayPointer(err) : nullptr;
  const long n = c->model.n_states;
  for (long i = 0; i < n; ++i) dy[i] = 0.0;
  for (int k = 0; k < c->model.n_free(); ++k) {
    const long o = kStatesPerBody * k + 3;
    const Vec4 q(y[o], y[o + 1], y[o + 2], y[o + 3]);
    const double norm = q.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) return 1;
    const Vec4 qn = q / norm;
    for (int j = 0; j < 4; ++j) dy[o + j] = qn(j) - q(j);
    if (e) {
      const Vec4 ev(e[o], e[o + 1], e[o + 2], e[o + 3]);
      const Vec4 pe = ev - qn * qn.dot(ev);
      for (int j = 0; j < 4; ++j) e[o + j] = pe(j);
    }
  }
  return 0;
}

TransientSample sample_at(const Model& model, Data& data, double t, const double* y) {
  set_state(model, data, y);
  compute_wrenches(model, data, t);
  TransientSample s;
  s.t = t;
  s.kinetic = kinetic_energy(model, data);
  s.elastic = data.elastic_energy;
  s.gravity = gravity_energy(model, data);
  return s;
}

std::vector<double> load_breakpoints(const Model& model, double t_end) {
  std::vector<double> all, inside;
  for (const Load& load : model.loads) load.time.append_breakpoints(all);
  std::sort(all.begin(), all.end());
  for (double t : all)
    if (t > 0.0 && t < t_end && (inside.empty() || t > inside.back())) inside.push_back(t);
  return inside;
}

std::string cvode_failure(int flag, const SundialsMessages& messages, const OdeContext& context) {
  if (!context.callback_error.empty())
    return "error while evaluating the model: " + context.callback_error;
  std::string why;
  switch (flag) {
    case CV_TOO_MUCH_WORK:
      why = "too many steps (max_steps reached)";
      break;
    case CV_TOO_MUCH_ACC:
      why = "the tolerances cannot be met (too much accuracy requested)";
      break;
    case CV_ERR_FAILURE:
      why = "repeated error-test failures";
      break;
    case CV_CONV_FAILURE:
      why = "the Newton iteration does not converge";
      break;
    case CV_RHSFUNC_FAIL:
    case CV_REPTD_RHSFUNC_ERR:
    case CV_UNREC_RHSFUNC_ERR:
      why = "the forces became non-finite (the motion diverged)";
      break;
    default:
      why = "CVODE flag " + std::to_string(flag);
  }
  if (!messages.last.empty()) why += " [" + messages.last + "]";
  return why;
}

}  // namespace

TransientResult run_transient(const Model& model, const TransientOptions& options, Data& data,
                              const TransientObserver& observer) {
  TransientResult result;
  const auto start = std::chrono::steady_clock::now();
  const IntegratorOptions& io = options.integrator;
  try {
    SundialsContext ctx;
    SundialsMessages messages;
    OdeContext context{model, data, {}, {}};
    const long n = model.n_states;
    SerialVector y(n, ctx);
    initial_state(model, y.data());

    void* mem = CVodeCreate(CV_BDF, ctx);
    struct MemoryOwner {
      void* m;
      ~MemoryOwner() { CVodeFree(&m); }
    } owner{mem};
    MatrixOwner matrix;
    LinearSolverOwner solver;
    CVodeSetErrHandlerFn(mem, &SundialsMessages::handler, &messages);
    CVodeInit(mem, rhs, 0.0, y);
    CVodeSStolerances(mem, io.rtol, io.atol);
    CVodeSetUserData(mem, &context);
    matrix.m = SUNDenseMatrix(n, n, ctx);
    solver.s = SUNLinSol_Dense(y, matrix.m, ctx);
    CVodeSetLinearSolver(mem, solver.s, matrix.m);
    if (io.jacobian == JacobianKind::kExact) CVodeSetJacFn(mem, dense_jacobian);
    CVodeSetProjFn(mem, project_quaternions);
    CVodeSetMaxOrd(mem, io.max_order);
    CVodeSetMaxNumSteps(mem, std::max(1L, io.max_steps));
    if (io.max_step > 0.0) CVodeSetMaxStep(mem, io.max_step);
    if (io.initial_step > 0.0) CVodeSetInitStep(mem, io.initial_step);

    const auto deliver = [&](double t) {
      const TransientSample s = sample_at(model, data, t, y.data());
      if (observer) observer(s, data);
    };
    deliver(0.0);

    const std::vector<double> breakpoints = load_breakpoints(model, options.t_end);
    size_t next_break = 0;
    const long n_out =
        std::max(1L, static_cast<long>(std::ceil(options.t_end / options.output_step - 1e-9)));
    double t = 0.0;
    result.ok = true;
    for (long k = 1; k <= n_out && result.ok; ++k) {
      const double t_out = std::min(static_cast<double>(k) * options.output_step, options.t_end);
      while (t < t_out) {
        // Never step across a load's jump: stop there and restart the multistep method.
        const bool at_break = next_break < breakpoints.size();
        const double stop = at_break ? breakpoints[next_break] : options.t_end;
        CVodeSetStopTime(mem, stop);
        const int flag = CVode(mem, std::min(t_out, stop), y, &t, CV_NORMAL);
        if (flag < 0) {
          result.ok = false;
          result.message = cvode_failure(flag, messages, context);
          break;
        }
        if (at_break && t >= stop) {
          ++next_break;
          CVodeReInit(mem, t, y);
        }
      }
      if (result.ok) deliver(t_out);
    }
    result.t_reached = t;

    SolverStats& s = result.stats;
    long fd_rhs = 0;
    CVodeGetNumSteps(mem, &s.steps);
    CVodeGetNumRhsEvals(mem, &s.rhs_evaluations);
    CVodeGetNumLinRhsEvals(mem, &fd_rhs);
    s.rhs_evaluations += fd_rhs;
    CVodeGetNumJacEvals(mem, &s.jacobian_evaluations);
    CVodeGetNumNonlinSolvIters(mem, &s.nonlinear_iterations);
    CVodeGetNumNonlinSolvConvFails(mem, &s.nonlinear_failures);
    CVodeGetNumErrTestFails(mem, &s.error_test_failures);
  } catch (const std::exception& e) {
    result.ok = false;
    result.message = e.what();
  }
  for (size_t r = 0; r < model.rails.size(); ++r)
    if (data.rail_floored_ever[r])
      result.warnings.push_back("rail \"" + model.rails[r].name + "\" reached its min_length");
  result.stats.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace beamrail
