// The check of the elements' own axial forces (core/analysis/axial_force_check.hpp) over a
// transient: at sampled output states, what the stiffness the beam law leaves out would change in
// the deformation (deformation_axial_force_effect, the response taken as quasi-static on the
// tangent of the state), the largest over the run worded as the run's warning. A tension from
// spinning (studies/spin_up.json) or a preload stiffens the bending in the real beam more than in
// the elements; a compression softens it more.
//
// Every output's element bound (MissingAxialForces::element_ratio_bound) is computed; a state is
// measured where it reaches kAxialForceNegligible and the state is one of about
// kAxialForceStates evenly over the outputs (the first and the last among them), or its bound is
// the largest yet (up to kAxialForceStates more: a pulse of force between the regular states).
// Cost per measured state: one tangent, one sparse factorization and a few solves (2 ms on the
// braced tower's 1,038 degrees of freedom). A state whose tangent cannot be factorized
// (singular above kAxialForceDenseLimit) is not measured (unmeasured(); the run warns when the
// largest bound among them reached kAxialForceWarning).
#pragma once

#include <memory>
#include <string>

#include "core/analysis/sparse_structure.hpp"
#include "core/analysis/static_newton.hpp"
#include "core/model/data.hpp"
#include "core/model/model.hpp"

namespace beamrail {

// Largest tangent a singular state (a free-floating structure, a mechanism) is measured on, by
// the dense minimum-norm solution (statics::TangentSolver::dense_limit): 50 free bodies, 15 ms
// a state.
inline constexpr long kAxialForceDenseLimit = 300;
// Most output states a transient's check measures.
inline constexpr int kAxialForceStates = 48;
// Below this bound on every element's missing part of its bending stiffness a state is not
// measured: 1e-4 of the warning. The bound is an element's; the structure's flexibility
// amplifies it in a result (near buckling: 0.999 of the load, 100 segments, a bound of 9.9e-5
// gave a static effect of 0.013), and the per-beam measure by up to 1 / kAxialForceFloor.
inline constexpr double kAxialForceNegligible = 1e-6;

class AxialForceWatch {
 public:
  // outputs: the run's number of output times after t = 0; the tangent's structure comes from
  // `cache` (nullptr: built) when a state is first measured.
  AxialForceWatch(const Model& model, SparseStructureCache* cache, long outputs);

  // The state in data (sampled at output `index`, 0 .. outputs, time t [s]).
  void observe(const Model& model, const Data& data, long index, double t);

  // The warning for the largest effect seen, "" below kAxialForceWarning.
  const std::string& warning() const { return warning_; }
  // The largest relative effect measured and when [s]; how many states were measured.
  double largest() const { return largest_; }
  double when() const { return when_; }
  int measured() const { return measured_; }
  // The wall time the check took [s].
  double seconds() const { return seconds_; }
  int unmeasured() const { return unmeasured_; }
  // The warning for states not measured, "" unless the largest bound among them reached
  // kAxialForceWarning.
  std::string unmeasured_warning() const;

 private:
  Data data_;
  SparseStructureCache* cache_ = nullptr;
  std::unique_ptr<statics::TangentSolver> solver_;
  long stride_ = 1, outputs_ = 0;
  double largest_ = 0.0, when_ = 0.0, seconds_ = 0.0;
  double largest_bound_ = 0.0, unmeasured_bound_ = 0.0;
  int measured_ = 0, unmeasured_ = 0, extra_ = 0;
  std::string warning_;
  std::string unmeasured_at_;  // when and why the state of the largest bound was not measured
};

}  // namespace beamrail
