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
  const auto start = std::chrono::steady_clock::now();
  struct Clock {
    std::chrono::steady_clock::time_point start;
    double* seconds;
    ~Clock() {
      *seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
  } clock{start, &seconds_};
  const MissingAxialForces missing(model, data);
  if (!missing.any()) return;
  const double bound = missing.element_ratio_bound();
  if (!(bound >= kAxialForceNegligible)) return;
  // The regular states, and any whose bound is the largest yet (a passing pulse of force).
  const bool regular = index % stride_ == 0 || index == outputs_;
  const bool peak = bound > largest_bound_ && extra_ < kAxialForceStates;
  largest_bound_ = std::max(largest_bound_, bound);
  if (!regular && !peak) return;
  if (!regular) ++extra_;
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
    if (bound > unmeasured_bound_) {
      unmeasured_bound_ = bound;
      char text[80];
      std::snprintf(text, sizeof text, "at t = %.6g s (", t);
      unmeasured_at_ = text + why + ")";
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

std::string AxialForceWatch::unmeasured_warning() const {
  if (!(unmeasured_bound_ >= kAxialForceWarning)) return "";
  char tail[120];
  std::snprintf(tail, sizeof tail,
                ": an element's own axial force changes its bending by up to %.3g of it",
                unmeasured_bound_);
  return "the check of the beams' axial forces could not measure " + std::to_string(unmeasured_) +
         " state(s), the one of the largest force " + unmeasured_at_ + tail +
         " (docs/model.md \"Axial force and bending\"; more segments reduce it as 1/n^2)";
}

}  // namespace beamrail
