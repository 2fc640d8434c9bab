#include "core/analysis/axial_force_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/model/element_kinematics.hpp"
#include "core/model/stiffness.hpp"

namespace beamrail {
namespace {

constexpr int kD = kDofsPerBody;
constexpr double kInf = std::numeric_limits<double>::infinity();

// How many elements would bring `relative` to 1 %: the effect falls as 1/n^2.
int segments_for(int elements, double relative) {
  if (!std::isfinite(relative)) return 0;
  return static_cast<int>(std::ceil(elements * std::sqrt(relative / kAxialForceWarning)));
}

std::string advice(const MissingAxialForces& missing, int beam, double relative) {
  const int n = missing.beam_elements()[beam];
  const double force = missing.beam_forces()[beam];
  const int needed = segments_for(n, relative);
  const std::string more =
      needed > n ? "; more segments reduce it as 1/n^2 (\"segments\": " + std::to_string(needed) +
                       " for 1 %)"
                 : "";
  return "mostly beam \"" + missing.beam_names()[beam] + "\" (" +
         (force < 0.0 ? "compressed, " : "stretched, ") + std::to_string(n) +
         (n == 1 ? " element" : " elements") +
         "): the beam law leaves out what an element's own axial force does to its bending (no "
         "P-delta within an element: docs/model.md \"Axial force and bending\")" +
         more;
}

// The largest of per-scene-beam values by magnitude; -1 when all are 0.
int largest(const std::vector<double>& values) {
  int which = -1;
  double most = 0.0;
  for (size_t g = 0; g < values.size(); ++g)
    if (std::abs(values[g]) > most) {
      most = std::abs(values[g]);
      which = static_cast<int>(g);
    }
  return which;
}

double sum(const std::vector<double>& values) {
  double s = 0.0;
  for (double v : values) s += v;
  return s;
}

// The largest relative change of a mode's frequency or a buckling factor, and where.
struct Worst {
  double size = 0.0;
  int mode = -1, beam = -1;
  void offer(double change, size_t i, const std::vector<double>& energy) {
    if (!(change > size)) return;
    size = change;
    mode = static_cast<int>(i);
    beam = largest(energy);
  }
  // "the axial forces of the beams change <what> N by about X of it ...", or with `infinite`
  // (its %d the mode's number) where the change has no size; "" below kAxialForceWarning.
  std::string worded(const char* what, const char* infinite,
                     const MissingAxialForces& missing) const {
    if (!(size > kAxialForceWarning) || beam < 0) return "";
    char text[300];
    if (std::isfinite(size))
      std::snprintf(text, sizeof text, "change %s %d by about %.3g of it", what, mode + 1, size);
    else
      std::snprintf(text, sizeof text, infinite, mode + 1);
    return "the axial forces of the beams " + std::string(text) + " beyond what the model holds, " +
           advice(missing, beam, size);
  }
};

// The correction e = -S^-1 (g0 + G e) of the displacements that the missing forces g0 of a state
// make (their own change G e included), by a fixed-point iteration; false, with e = -S^-1 g0,
// when it diverges.
bool correction(const MissingAxialForces& missing, const Eigen::VectorXd& g0,
                const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& solve,
                Eigen::VectorXd* out) {
  Eigen::VectorXd& e = *out;
  e = -solve(g0);
  // Growing 1e6 times past the first-order correction is divergence (and keeps the norms below
  // overflow, where inf <= inf once passed for convergence).
  const double most = 1e6 * e.norm();
  double change = kInf;
  for (int it = 0; it < 100 && e.allFinite() && e.norm() <= most; ++it) {
    const Eigen::VectorXd next = -solve(g0 + missing.of(e));
    change = (next - e).norm();
    e = next;
    if (change <= 1e-3 * e.norm()) break;
  }
  if (e.allFinite() && e.norm() <= most && change <= 1e-2 * e.norm()) return true;
  e = -solve(g0);
  return false;
}

// Per free body, its correction over its displacement along it (at least kAxialForceFloor of the
// largest displacement of any body); the largest. 0 when nothing moved.
double body_relative(const Model& model, const Data& data, const Eigen::VectorXd& e) {
  double moved = 0.0;
  for (int b : model.free_bodies) moved = std::max(moved, data.pose[b].u.norm());
  if (!(moved > 0.0)) return 0.0;
  const double floor = kAxialForceFloor * moved;
  double relative = 0.0;
  for (int b : model.free_bodies) {
    const int k = model.bodies[b].free_index;
    const Vec3 c = e.segment<3>(kD * k);
    if (!(c.norm() > 0.0)) continue;
    const double along = std::abs(data.pose[b].u.dot(c.normalized()));
    relative = std::max(relative, c.norm() / std::max(along, floor));
  }
  return relative;
}

}  // namespace

MissingAxialForces::MissingAxialForces(const Model& model, const Data& data) : n_(model.n_dofs) {
  build(model, data, nullptr);
}

MissingAxialForces::MissingAxialForces(const Model& model, const Data& data,
                                       const Eigen::VectorXd& direction)
    : n_(model.n_dofs) {
  build(model, data, &direction);
}

void MissingAxialForces::build(const Model& model, const Data& data,
                               const Eigen::VectorXd* direction) {
  for (const Beam& b : model.beams) {
    const std::string& group = b.group.empty() ? b.name : b.group;
    int g = 0;
    while (g < static_cast<int>(names_.size()) && names_[g] != group) ++g;
    if (g == static_cast<int>(names_.size())) {
      names_.push_back(group);
      counts_.push_back(0);
      forces_.push_back(0.0);
    }
    ++counts_[g];
    const double l = b.ends.length;
    if (!(l > 0.0)) continue;
    const ElementFrames<double> f = element_frames(b.ends, data.pose[b.ends.body1],
                                                   data.pose[b.ends.body2], rotation_measure(b));
    Element e;
    e.free1 = model.bodies[b.ends.body1].free_index;
    e.free2 = model.bodies[b.ends.body2].free_index;
    if (e.free1 < 0 && e.free2 < 0) continue;
    e.beam = g;
    e.e1 = f.E1;
    e.t = f.t;
    e.r2 = f.R2;
    e.lever1 = f.lever1;
    e.offset = f.xi;
    e.turn = f.phi;
    e.l = l;
    if (direction) {
      Vec3 dxi, dphi;
      change(e, *direction, &dxi, &dphi);
      e.n = b.ea * dxi(0) / l;
    } else {
      e.n = b.ea * (f.xi(0) - l) / l;
    }
    if (!std::isfinite(e.n)) continue;
    e.eiy = b.eiy;
    e.eiz = b.eiz;
    e.ea = b.ea;
    e.gj = b.gj;
    if (e.n != 0.0) {
      ++loaded_;
      if (std::abs(e.n) > std::abs(forces_[g])) forces_[g] = e.n;
    }
    elements_.push_back(e);
  }
}

bool MissingAxialForces::compressed() const {
  for (const Element& e : elements_)
    if (e.n < 0.0) return true;
  return false;
}

void MissingAxialForces::change(const Element& e, const Eigen::VectorXd& v, Vec3* dxi,
                                Vec3* dphi) const {
  // d xi = E1^T (dc2 - dc1 - R2 x dtheta2 + (p2 - c1) x dtheta1), d phi = T E1^T (dtheta2 -
  // dtheta1) (docs/model.md "Beams").
  Vec3 d = Vec3::Zero(), turn = Vec3::Zero();
  if (e.free2 >= 0) {
    const Vec3 dc = v.segment<3>(kD * e.free2), dt = v.segment<3>(kD * e.free2 + 3);
    d += dc - e.r2.cross(dt);
    turn += dt;
  }
  if (e.free1 >= 0) {
    const Vec3 dc = v.segment<3>(kD * e.free1), dt = v.segment<3>(kD * e.free1 + 3);
    d += -dc + e.lever1.cross(dt);
    turn -= dt;
  }
  *dxi = e.e1.transpose() * d;
  *dphi = e.t * (e.e1.transpose() * turn);
}

void MissingAxialForces::local_forces(const Element& e, const Vec3& xi, const Vec3& phi, Vec3* f,
                                      Vec3* m) {
  // Per plane, -N / (30 l) [36, -3 l; -3 l, 4 l^2] (v, t): x-y with (xi_y, phi_z), x-z with
  // (xi_z, -phi_y).
  const double c = e.n / (30.0 * e.l), l = e.l;
  const auto plane = [&](double v, double t, double* force, double* moment) {
    *force = -c * (36.0 * v - 3.0 * l * t);
    *moment = -c * (-3.0 * l * v + 4.0 * l * l * t);
  };
  double fy, mz, fz, my;
  plane(xi(1), phi(2), &fy, &mz);
  plane(xi(2), -phi(1), &fz, &my);
  *f = Vec3(0.0, fy, fz);
  *m = Vec3(0.0, -my, mz);
}

void MissingAxialForces::add(const Element& e, const Vec3& f, const Vec3& m,
                             Eigen::VectorXd& out) const {
  // The virtual work f . d xi + m . d phi: the transpose of change().
  const Vec3 force = e.e1 * f, moment = e.e1 * (e.t.transpose() * m);
  if (e.free2 >= 0) {
    out.segment<3>(kD * e.free2) += force;
    out.segment<3>(kD * e.free2 + 3) += e.r2.cross(force) + moment;
  }
  if (e.free1 >= 0) {
    out.segment<3>(kD * e.free1) -= force;
    out.segment<3>(kD * e.free1 + 3) -= e.lever1.cross(force) + moment;
  }
}

Eigen::VectorXd MissingAxialForces::at_state() const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(n_);
  for (const Element& e : elements_) {
    Vec3 f, m;
    local_forces(e, e.offset, e.turn, &f, &m);
    add(e, f, m, out);
  }
  return out;
}

Eigen::VectorXd MissingAxialForces::of(const Eigen::VectorXd& v) const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(n_);
  for (const Element& e : elements_) {
    Vec3 dxi, dphi, f, m;
    change(e, v, &dxi, &dphi);
    local_forces(e, dxi, dphi, &f, &m);
    add(e, f, m, out);
  }
  return out;
}

std::vector<double> MissingAxialForces::stiffness_energy(const Eigen::VectorXd& v) const {
  std::vector<double> out(names_.size(), 0.0);
  for (const Element& e : elements_) {
    Vec3 dxi, dphi, f, m;
    change(e, v, &dxi, &dphi);
    local_forces(e, dxi, dphi, &f, &m);
    out[e.beam] -= f.dot(dxi) + m.dot(dphi);
  }
  return out;
}

std::vector<double> MissingAxialForces::bending_energy(const Eigen::VectorXd* v) const {
  std::vector<double> out(names_.size(), 0.0);
  for (const Element& e : elements_) {
    Vec3 xi = e.offset, phi = e.turn;
    if (v) change(e, *v, &xi, &phi);
    const StiffnessBlocks<double> k(e.ea, e.gj, e.eiy, e.eiz, e.l);
    Vec6 d;
    d << 0.0, xi(1), xi(2), 0.0, phi(1), phi(2);
    out[e.beam] += d.dot(k.k2(d));
  }
  return out;
}

double MissingAxialForces::element_ratio_bound() const {
  // det(K_s - r K_b) = 0 per plane, K_s = N / (30 l) [36, -3 l; -3 l, 4 l^2], K_b = EI / l^3
  // [12, -6 l; -6 l, 4 l^2]: 12 r^2 - 5.2 r s + 0.15 s^2 = 0 with s = N l^2 / EI, whose larger
  // root is r = (5.2 + sqrt(19.84)) / 24 s = 0.4023 s.
  constexpr double kLargest = 0.40225;
  double bound = 0.0;
  for (const Element& e : elements_) {
    const double ei = std::min(e.eiy, e.eiz);
    if (e.n == 0.0) continue;
    if (!(ei > 0.0)) return kInf;
    bound = std::max(bound, kLargest * std::abs(e.n) * e.l * e.l / ei);
  }
  return bound;
}

AxialForceEffect deformation_axial_force_effect(
    const MissingAxialForces& missing,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& solve) {
  AxialForceEffect effect;
  if (!missing.any()) return effect;
  const Eigen::VectorXd g0 = missing.at_state();
  if (!(g0.squaredNorm() > 0.0)) return effect;
  // Where the iteration diverges (the missing stiffness outweighs the structure's along e: in
  // tension it only stiffens, in compression it may leave none), correction's first-order e,
  // whose measure is then large: a warning either way.
  Eigen::VectorXd e;
  correction(missing, g0, solve, &e);
  if (!e.allFinite()) return effect;
  const std::vector<double> state = missing.bending_energy(nullptr);
  const std::vector<double> change = missing.bending_energy(&e);
  double most = 0.0;
  for (double b : state) most = std::max(most, b);
  if (!(most > 0.0)) return effect;
  for (size_t g = 0; g < state.size(); ++g) {
    if (!(state[g] >= kAxialForceFloor * kAxialForceFloor * most)) continue;
    const double relative = std::sqrt(change[g] / state[g]);
    if (relative > effect.relative) {
      effect.relative = relative;
      effect.beam = static_cast<int>(g);
    }
  }
  if (effect.beam < 0) effect.beam = largest(missing.beam_forces());
  return effect;
}

std::string transient_axial_force_warning(const MissingAxialForces& missing,
                                          const AxialForceEffect& effect, double t) {
  if (effect.beam < 0 || !(effect.relative > kAxialForceWarning)) return "";
  char text[300];
  if (std::isfinite(effect.relative))
    std::snprintf(text, sizeof text,
                  "the axial forces of the beams change the deformation by about %.3g of it (at "
                  "t = %.6g s, the largest of the states measured) beyond what the model holds, ",
                  effect.relative, t);
  else
    std::snprintf(text, sizeof text,
                  "the axial forces of the beams change the deformation by more than it is (at "
                  "t = %.6g s) beyond what the model holds, ",
                  t);
  return text + advice(missing, effect.beam, effect.relative);
}

AxialForceEffect static_axial_force_effect(
    const Model& model, const Data& data, const MissingAxialForces& missing,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& solve) {
  AxialForceEffect effect;
  if (!missing.any()) return effect;
  const Eigen::Index n = model.n_dofs;
  // Stability with the missing stiffness: the lowest eigenvalue of A = S^-1 G (real: K^-1 K_s
  // with K positive definite) by power iterations, shifted by the dominant one when that is
  // positive; at or below -1, K + K_s is not positive definite.
  if (missing.compressed()) {
    const auto dominant = [&](double shift, int iterations) {
      Eigen::VectorXd x(n);
      for (Eigen::Index i = 0; i < n; ++i) x(i) = std::sin(1.0 + 0.7 * static_cast<double>(i));
      x.normalize();
      double value = 0.0;
      for (int it = 0; it < iterations; ++it) {
        Eigen::VectorXd y = solve(missing.of(x)) - shift * x;
        if (!y.allFinite()) return 0.0;
        value = x.dot(y);
        const double size = y.norm();
        if (!(size > 0.0)) return 0.0;
        x = y / size;
      }
      return value + shift;
    };
    double lowest = dominant(0.0, 40);
    if (lowest > 0.0) lowest = dominant(lowest, 60);
    effect.unstable = lowest <= -1.0;
  }
  const Eigen::VectorXd g0 = missing.at_state();
  double moved = 0.0;
  for (int b : model.free_bodies) moved = std::max(moved, data.pose[b].u.norm());
  Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
  if (moved > 0.0 && g0.squaredNorm() > 0.0) {
    if (!correction(missing, g0, solve, &e))
      effect.relative = kInf;
    else
      effect.relative = body_relative(model, data, e);
  }
  if (!e.allFinite()) e = Eigen::VectorXd::Zero(n);
  effect.beam = largest(missing.stiffness_energy(e));
  if (effect.beam < 0) effect.beam = largest(missing.beam_forces());
  return effect;
}

std::string static_axial_force_warning(const MissingAxialForces& missing,
                                       const AxialForceEffect& effect) {
  if (effect.beam < 0) return "";
  char text[300];
  if (effect.unstable)
    std::snprintf(text, sizeof text,
                  "the axial forces of the beams would make this equilibrium unstable (buckled) "
                  "beyond what the model holds, ");
  else if (!(effect.relative > kAxialForceWarning))
    return "";
  else if (std::isfinite(effect.relative))
    std::snprintf(text, sizeof text,
                  "the axial forces of the beams change the displacements by about %.3g of "
                  "them beyond what the model holds, ",
                  effect.relative);
  else
    std::snprintf(text, sizeof text,
                  "the axial forces of the beams change the displacements by more than they "
                  "are beyond what the model holds, ");
  return text + advice(missing, effect.beam, effect.unstable ? kInf : effect.relative);
}

std::string buckling_axial_force_warning(const MissingAxialForces& reference,
                                         const MissingAxialForces& per_factor,
                                         const std::vector<Eigen::VectorXd>& shapes,
                                         const std::vector<double>& factors,
                                         const std::vector<double>& stiffness) {
  if (!reference.any() && !per_factor.any()) return "";
  Worst worst;
  for (size_t i = 0; i < shapes.size(); ++i) {
    if (!(factors[i] > 0.0) || !(stiffness[i] > 0.0)) continue;
    const std::vector<double> e1 = per_factor.stiffness_energy(shapes[i]);
    const double numerator = stiffness[i] + sum(reference.stiffness_energy(shapes[i]));
    const double denominator = stiffness[i] / factors[i] - sum(e1);
    worst.offer(denominator > 0.0 && numerator > 0.0
                    ? std::abs(numerator / denominator / factors[i] - 1.0)
                    : kInf,
                i, e1);
  }
  return worst.worded("buckling factor",
                      "leave buckling factor %d without meaning (the stiffness they leave out "
                      "outweighs the shape's)",
                      per_factor);
}

std::string modal_axial_force_warning(const MissingAxialForces& missing,
                                      const std::vector<Eigen::VectorXd>& shapes,
                                      const std::vector<double>& eigenvalues) {
  if (!missing.any()) return "";
  Worst worst;
  for (size_t i = 0; i < shapes.size(); ++i) {
    if (!(eigenvalues[i] > 0.0)) continue;
    const std::vector<double> energy = missing.stiffness_energy(shapes[i]);
    // w'^2 = w^2 + x^T K_s x: the relative change of the frequency.
    const double ratio = 1.0 + sum(energy) / eigenvalues[i];
    worst.offer(ratio > 0.0 ? std::abs(std::sqrt(ratio) - 1.0) : kInf, i, energy);
  }
  return worst.worded("the frequency of mode", "would make mode %d unstable", missing);
}

}  // namespace beamrail
