#include "core/analysis/axial_force_check.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "core/model/element_kinematics.hpp"

namespace beamrail {
namespace {

constexpr int kD = kDofsPerBody;

// How much more a beam of n elements would need: the effect falls as 1/n^2.
int segments_for(int elements, double relative) {
  if (!std::isfinite(relative)) return 0;
  return static_cast<int>(std::ceil(elements * std::sqrt(relative / kAxialForceWarning)));
}

std::string advice(const MissingAxialForces& missing, int beam, double relative) {
  const int n = missing.beam_elements()[beam];
  const double force = missing.beam_forces()[beam];
  char text[400];
  const int needed = segments_for(n, relative);
  std::snprintf(text, sizeof text,
                "mostly beam \"%s\" (%s, %d element%s): the beam law leaves out what an "
                "element's own axial force does to its bending (no P-delta within an element: "
                "docs/model.md \"Axial force and bending\")%s",
                missing.beam_names()[beam].c_str(), force < 0.0 ? "compressed" : "stretched", n,
                n == 1 ? "" : "s",
                needed > n ? (std::string("; more segments reduce it as 1/n^2 (\"segments\": ") +
                              std::to_string(needed) + " for 1 %)")
                                 .c_str()
                           : "");
  return text;
}

}  // namespace

MissingAxialForces::MissingAxialForces(const Model& model, const Data& data) : n_(model.n_dofs) {
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
    const double force = b.ea * (f.xi(0) - l) / l;
    if (!(force != 0.0) || !std::isfinite(force)) continue;
    if (std::abs(force) > std::abs(forces_[g])) forces_[g] = force;
    Element e;
    e.free1 = model.bodies[b.ends.body1].free_index;
    e.free2 = model.bodies[b.ends.body2].free_index;
    if (e.free1 < 0 && e.free2 < 0) continue;
    e.beam = g;
    e.e1 = f.E1;
    e.r2 = f.R2;
    e.lever1 = f.lever1;
    e.offset = f.xi;
    e.k = kStringStiffnessFactor * force / l;
    elements_.push_back(e);
  }
}

Vec3 MissingAxialForces::offset_change(const Element& e, const Eigen::VectorXd& v) const {
  // d xi = E1^T (dc2 - dc1 - R2 x dtheta2 + (p2 - c1) x dtheta1) (docs/model.md "Beams").
  Vec3 d = Vec3::Zero();
  if (e.free2 >= 0) {
    const Vec3 dc = v.segment<3>(kD * e.free2), dt = v.segment<3>(kD * e.free2 + 3);
    d += dc - e.r2.cross(dt);
  }
  if (e.free1 >= 0) {
    const Vec3 dc = v.segment<3>(kD * e.free1), dt = v.segment<3>(kD * e.free1 + 3);
    d += -dc + e.lever1.cross(dt);
  }
  return e.e1.transpose() * d;
}

void MissingAxialForces::add(const Element& e, const Vec3& f, Eigen::VectorXd& out) const {
  // The virtual work f . d(p2 - p1) with d(p2 - p1) = E1 d xi: the transpose of offset_change.
  if (e.free2 >= 0) {
    out.segment<3>(kD * e.free2) += f;
    out.segment<3>(kD * e.free2 + 3) += e.r2.cross(f);
  }
  if (e.free1 >= 0) {
    out.segment<3>(kD * e.free1) -= f;
    out.segment<3>(kD * e.free1 + 3) -= e.lever1.cross(f);
  }
}

Eigen::VectorXd MissingAxialForces::at_state() const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(n_);
  for (const Element& e : elements_)
    add(e, e.e1 * Vec3(0.0, -e.k * e.offset(1), -e.k * e.offset(2)), out);
  return out;
}

Eigen::VectorXd MissingAxialForces::of(const Eigen::VectorXd& v) const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(n_);
  for (const Element& e : elements_) {
    const Vec3 d = offset_change(e, v);
    add(e, e.e1 * Vec3(0.0, -e.k * d(1), -e.k * d(2)), out);
  }
  return out;
}

std::vector<double> MissingAxialForces::stiffness_energy(const Eigen::VectorXd& v) const {
  std::vector<double> out(names_.size(), 0.0);
  for (const Element& e : elements_) {
    const Vec3 d = offset_change(e, v);
    out[e.beam] += e.k * (d(1) * d(1) + d(2) * d(2));
  }
  return out;
}

AxialForceEffect static_axial_force_effect(
    const Model& model, const Data& data, const MissingAxialForces& missing,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& solve) {
  AxialForceEffect effect;
  if (!missing.any()) return effect;
  double moved = 0.0;
  for (int b : model.free_bodies) moved = std::max(moved, data.pose[b].u.norm());
  if (!(moved > 0.0)) return effect;
  const Eigen::VectorXd g0 = missing.at_state();
  const auto largest = [&](const Eigen::VectorXd& v) {
    double m = 0.0;
    for (Eigen::Index k = 0; k < v.size() / kD; ++k) m = std::max(m, v.segment<3>(kD * k).norm());
    return m;
  };
  Eigen::VectorXd e = -solve(g0);
  if (!e.allFinite()) return effect;
  // e = -S^-1 (g0 + G e): the missing forces of the corrected state; a contraction unless the
  // left-out compression softens the structure past its stiffness.
  double size = largest(e);
  for (int it = 0; it < 100; ++it) {
    const Eigen::VectorXd next = -solve(g0 + missing.of(e));
    if (!next.allFinite()) break;
    const double change = largest(next - e);
    e = next;
    const double previous = size;
    size = largest(e);
    if (change <= 1e-3 * size) break;
    if (it > 10 && size > 1.5 * previous) {  // growing: diverges
      size = std::numeric_limits<double>::infinity();
      break;
    }
    if (it == 99) size = std::numeric_limits<double>::infinity();
  }
  effect.relative = size / moved;
  // The beam whose missing stiffness the correction works against most.
  const std::vector<double> energy = missing.stiffness_energy(e.allFinite() ? e : -solve(g0));
  double most = -1.0;
  for (size_t g = 0; g < energy.size(); ++g)
    if (std::abs(energy[g]) > most) {
      most = std::abs(energy[g]);
      effect.beam = static_cast<int>(g);
    }
  return effect;
}

std::string static_axial_force_warning(const MissingAxialForces& missing,
                                       const AxialForceEffect& effect) {
  if (!(effect.relative > kAxialForceWarning) || effect.beam < 0) return "";
  char text[300];
  if (std::isfinite(effect.relative))
    std::snprintf(text, sizeof text,
                  "the axial forces of the beams change the displacements by about %.3g of "
                  "them beyond what the model holds, ",
                  effect.relative);
  else
    std::snprintf(text, sizeof text,
                  "the axial forces of the beams change the displacements by more than they "
                  "are (with them the structure would buckle), beyond what the model holds, ");
  return text + advice(missing, effect.beam, effect.relative);
}

std::string modal_axial_force_warning(const MissingAxialForces& missing,
                                      const std::vector<Eigen::VectorXd>& shapes,
                                      const std::vector<double>& eigenvalues) {
  if (!missing.any()) return "";
  double worst = 0.0;
  int mode = -1, beam = -1;
  for (size_t i = 0; i < shapes.size(); ++i) {
    if (!(eigenvalues[i] > 0.0)) continue;
    const std::vector<double> energy = missing.stiffness_energy(shapes[i]);
    double sum = 0.0, most = -1.0;
    int which = -1;
    for (size_t g = 0; g < energy.size(); ++g) {
      sum += energy[g];
      if (std::abs(energy[g]) > most) {
        most = std::abs(energy[g]);
        which = static_cast<int>(g);
      }
    }
    // w'^2 = w^2 + x^T K_s x: the relative change of the frequency.
    const double relative = std::sqrt(std::max(0.0, 1.0 + sum / eigenvalues[i])) - 1.0;
    const double size = 1.0 + sum / eigenvalues[i] > 0.0 ? std::abs(relative)
                                                         : std::numeric_limits<double>::infinity();
    if (size > worst) {
      worst = size;
      mode = static_cast<int>(i);
      beam = which;
    }
  }
  if (!(worst > kAxialForceWarning) || beam < 0) return "";
  char text[300];
  if (std::isfinite(worst))
    std::snprintf(text, sizeof text,
                  "the axial forces of the beams change the frequency of mode %d by about %.3g "
                  "of it beyond what the model holds, ",
                  mode + 1, worst);
  else
    std::snprintf(text, sizeof text,
                  "the axial forces of the beams would make mode %d unstable beyond what the "
                  "model holds, ",
                  mode + 1);
  return text + advice(missing, beam, worst);
}

}  // namespace beamrail
