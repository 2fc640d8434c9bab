#include "core/analysis/axial_force_watch.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "core/analysis/axial_force_check.hpp"
#include "core/model/forces.hpp"

namespace beamrail {

AxialForceWatch::AxialForceWatch(const Model& model, SparseStructureCache* cache, long outputs)
    : data_(model),
      cache_(cache),
      stride_(std::max(1L, (outputs + kAxialForceStates - 1) / kAxialForceStates)),
      outputs_(outputs) {}

void AxialForceWatch::observe(const Model& model, const Data& data, long index, double t) {
  if (index % stride_ != 0 && index != outputs_) return;
  const auto start = std::chrono::steady_clock::now();
  struct Clock {
    std::chrono::steady_clock::time_point start;
    double* seconds;
    ~Clock() {
      *seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
  } clock{start, &seconds_};
  const MissingAxialForces missing(model, data);
  if (!missing.any() || missing.element_ratio_bound() < kAxialForceNegligible) return;
  if (!solver_) {
    solver_ = std::make_unique<statics::TangentSolver>(
        cache_ ? cache_->get(model) : std::make_shared<const SparseStructure>(model));
    solver_->dense_limit = kAxialForceDenseLimit;
  }
  data_.pose = data.pose;
  data_.q = data.q;
  data_.w = data.w;
  compute_tangent(model, data_, t, false, 1.0);
  std::string why;
  if (!solver_->factorize(model, data_, &why)) {
    ++unmeasured_;
    const double bound = missing.element_ratio_bound();
    if (bound >= kAxialForceWarning && unmeasured_warning_.empty()) {
      char text[160];
      std::snprintf(text, sizeof text,
                    "the check of the beams' axial forces could not measure the state at t = "
                    "%.6g s (%s)",
                    t, why.c_str());
      char bound_text[40];
      std::snprintf(bound_text, sizeof bound_text, "%.3g", bound);
      unmeasured_warning_ = std::string(text) +
                            ": an element's own axial force may change its bending by up to " +
                            bound_text + " of it (docs/model.md \"Axial force and bending\")";
    }
    return;
  }
  ++measured_;
  const AxialForceEffect effect = deformation_axial_force_effect(
      missing, [&](const Eigen::VectorXd& b) { return solver_->solve(b); });
  if (!(effect.relative > largest_)) return;
  largest_ = effect.relative;
  when_ = t;
  warning_ = transient_axial_force_warning(missing, effect, t);
}

}  // namespace beamrail
