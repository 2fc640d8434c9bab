// The time integrators of the transient analysis behind one small interface: CVODE (BDF, Adams)
// and ARKODE (diagonally implicit Runge-Kutta tables, explicit Runge-Kutta tables), with dense or
// sparse (KLU) linear algebra for the implicit ones.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/analysis/ode_system.hpp"
#include "core/analysis/sundials_support.hpp"
#include "core/analysis/transient.hpp"

namespace beamrail {

class Integrator {
 public:
  virtual ~Integrator() = default;
  // Integrates to tout without stepping past tstop; y and *t receive the result. Returns a
  // SUNDIALS flag (< 0: failure).
  virtual int advance(double tout, double tstop, N_Vector y, double* t) = 0;
  // Restarts from (t, y) after a jump in the loads.
  virtual void restart(double t, N_Vector y) = 0;
  virtual SolverStats stats() const = 0;
  // A sentence on why advance() returned flag.
  virtual std::string failure(int flag) const = 0;
  // "dense", "sparse" or "none" (explicit methods).
  std::string linear_solver = "none";
  long nnz = 0;                       // stored Jacobian entries (sparse)
  std::vector<std::string> warnings;  // for the run's result (set up at construction)
  // Warnings that only the whole run can tell (a band-limited modal run's dropped inertia), asked
  // for at its end.
  virtual std::vector<std::string> closing_warnings() const { return {}; }
  // The highest frequency a band-limited modal method integrated [Hz], given or chosen (auto: the
  // highest of its modal phases); 0 when every mode was integrated or the method has no band.
  double band_hz = 0.0;
  // Called as each phase after the first begins (TransientOptions::phase_started); empty: none.
  std::function<void(const MethodPhase&)> phase_started;
  // The phases so far (auto switches methods and relinearizes; others have none) and their count.
  virtual std::vector<MethodPhase> phases(long* count) const {
    *count = 0;
    return {};
  }
};

// Builds the integrator of options.method for the system in `context`, starting at (0, y0).
// Returns nullptr with *error set when an option is unusable.
std::unique_ptr<Integrator> make_integrator(const IntegratorOptions& options, OdeContext& context,
                                            SUNContext sunctx, N_Vector y0, std::string* error);

}  // namespace beamrail
