// Plausibility warnings for a scene that loads but looks mistyped: a dimension in millimetres where
// metres were meant makes a member's section a million times the others', a wrong coordinate puts
// a beam's end metres away from its body. Each is a warning with its JSON pointer, never an error:
// the scene may mean it.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <vector>

#include "core/scene/scene_specs.hpp"

namespace beamrail {
namespace {

// Two orders of magnitude from the median of the scene's members.
constexpr double kOrders = 100.0;
// A point farther from its body's centre than this many radii of gyration (and than the median
// member length) lies outside any plausible extent of the body.
constexpr double kGyrationRadii = 3.0;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string g3(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

// "1200 times" or "1/1200 of".
std::string ratio_text(double value, double reference) {
  return value >= reference ? g3(value / reference) + " times"
                            : "1/" + g3(reference / value) + " of";
}

bool orders_away(double value, double reference) {
  return reference > 0.0 && value > 0.0 &&
         (value > kOrders * reference || value * kOrders < reference);
}

std::string element_word(const ElementSpec& e) { return e.rail ? "rail" : "beam"; }

}  // namespace

void check_plausibility(const SceneSpecs& specs, const Where& scene, Diagnostics& diag) {
  const std::vector<ElementSpec>& elements = specs.elements;
  std::vector<double> lengths, areas, masses;
  for (const ElementSpec& e : elements) {
    const double l = (e.p2 - e.p1).norm();
    lengths.push_back(l);
    areas.push_back(e.section.area);
    if (e.material.density > 0.0) masses.push_back(e.material.density * e.section.area * l);
  }
  const double length_scale = lengths.empty() ? 0.0 : median(lengths);

  // Members against the rest (when there is a rest: three members or more).
  if (elements.size() >= 3) {
    const double l0 = median(lengths), s0 = median(areas);
    const double m0 = masses.size() >= 3 ? median(masses) : 0.0;
    std::set<std::string> sections_reported;
    for (const ElementSpec& e : elements) {
      const double l = (e.p2 - e.p1).norm(), s = e.section.area;
      const std::string who = element_word(e) + " \"" + e.name + "\"";
      bool reported = false;
      if (orders_away(l, l0)) {
        diag.warning(e.where.file, (e.where / "point2").pointer,
                     who + " is " + g3(l) + " m long, " + ratio_text(l, l0) +
                         " the median length of the scene's members (" + g3(l0) +
                         " m): is a point mistyped?");
        reported = true;
      }
      if (orders_away(s, s0)) {
        reported = true;
        if (sections_reported.insert(e.section_name).second)
          diag.warning(scene.file, (scene / "sections" / e.section_name).pointer,
                       "section \"" + e.section_name + "\" (of " + who + ") has an area of " +
                           g3(s) + " m^2, " + ratio_text(s, s0) +
                           " the median of the scene's members (" + g3(s0) +
                           " m^2): a dimension in millimetres instead of metres?");
      }
      const double m = e.material.density * s * l;
      if (!reported && e.material.density > 0.0 && orders_away(m, m0))
        diag.warning(e.where.file, e.where.pointer,
                     who + " weighs " + g3(m) + " kg, " + ratio_text(m, m0) +
                         " the median of the scene's members (" + g3(m0) +
                         " kg): is the density "
                         "of material \"" +
                         e.material_name + "\" (" + g3(e.material.density) +
                         " kg/m^3) or its section mistyped?");
    }
  }

  // Points far from their bodies.
  if (!(length_scale > 0.0)) return;
  const auto far_point = [&](int body, const Vec3& point, const Where& at,
                             const std::string& what) {
    const BodySpec& b = specs.bodies[body];
    if (b.fixed || b.generated) return;
    double gyration = 0.0;
    if (b.mass && b.inertia && *b.mass > 0.0) {
      const Eigen::SelfAdjointEigenSolver<Mat3> eig(*b.inertia);
      gyration = std::sqrt(std::max(0.0, eig.eigenvalues().maxCoeff()) / *b.mass);
    }
    const double d = (point - b.position).norm();
    if (!(d > kGyrationRadii * gyration && d > length_scale)) return;
    diag.warning(at.file, at.pointer,
                 what + " is " + g3(d) + " m from the centre of body \"" + b.name +
                     "\", beyond its extent (" + g3(kGyrationRadii) + " radii of gyration: " +
                     g3(kGyrationRadii * gyration) + " m) and the median member length (" +
                     g3(length_scale) + " m): is it mistyped, or attached to the wrong body?");
  };
  for (const ElementSpec& e : elements) {
    far_point(e.body1, e.p1, e.where / "point1",
              "point1 of " + element_word(e) + " \"" + e.name + "\"");
    far_point(e.body2, e.p2, e.where / "point2",
              "point2 of " + element_word(e) + " \"" + e.name + "\"");
  }
  for (size_t k = 0; k < specs.loads.size() && k < specs.load_where.size(); ++k)
    if (specs.loads[k].kind == LoadKind::kForce)
      far_point(specs.loads[k].body, specs.load_points[k], specs.load_where[k] / "point",
                "the point of this force");
}

}  // namespace beamrail
