// Readers of the scene's materials, sections, bodies, beams, rails, joints and loads.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/model/hyper_dual.hpp"
#include "core/model/rotation.hpp"
#include "core/model/section.hpp"
#include "core/scene/scene_specs.hpp"

namespace beamrail {
namespace {

// The highest frequency of a harmonic time function [Hz].
constexpr double kMaxHarmonicFrequency = 1e12;

std::string number_text(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

// Iterates the members of an optional object member; reports a non-object.
template <class F>
void for_each_member(ObjectReader& parent, const std::string& key, F&& f) {
  const Json* obj = parent.member(key, false);
  if (!obj) return;
  if (!obj->is_object()) {
    parent.error(key, "expected an object of named entries, got " + json_type_name(*obj));
    return;
  }
  for (const auto& item : obj->items()) f(item.key(), item.value(), parent.at(key) / item.key());
}

// Iterates the entries of an optional array member; reports a non-array.
template <class F>
void for_each_entry(ObjectReader& parent, const std::string& key, F&& f) {
  const Json* arr = parent.member(key, false);
  if (!arr) return;
  if (!arr->is_array()) {
    parent.error(key, "expected an array, got " + json_type_name(*arr));
    return;
  }
  for (size_t i = 0; i < arr->size(); ++i) f((*arr)[i], parent.at(key) / i);
}

template <class S>
std::optional<SectionPropertiesT<S>> read_section(ObjectReader& r, const SceneSpecsT<S>& specs) {
  const auto number = [&](const std::string& key, bool required) {
    return seeded(specs, r.positive(key, required), r.at(key));
  };
  const auto shape = r.choice("shape", true, {"rectangle", "circle", "tube", "box", "custom"});
  if (!shape) {
    r.allow({"width", "height", "diameter", "outer_diameter", "wall", "S", "Ix", "Iy", "Iz", "Wy",
             "Wz"});
    return std::nullopt;
  }
  if (*shape == "rectangle") {
    const auto w = number("width", true), h = number("height", true);
    if (w && h) return rectangle_section(*w, *h);
  } else if (*shape == "circle") {
    if (const auto d = number("diameter", true)) return circle_section(*d);
  } else if (*shape == "tube") {
    const auto d = number("outer_diameter", true), t = number("wall", true);
    if (d && t) {
      if (*t < 0.5 * *d) return tube_section(*d, *t);
      r.error("wall",
              "must be less than half the outer diameter (" + number_text(value_of(*d) / 2) + ")");
    }
  } else if (*shape == "box") {
    const auto w = number("width", true), h = number("height", true);
    const auto t = number("wall", true);
    if (w && h && t) {
      if (*t < 0.5 * std::min(value_of(*w), value_of(*h))) return box_section(*w, *h, *t);
      r.error("wall", "must be less than half the smaller of width and height");
    }
  } else {
    SectionPropertiesT<S> s;
    const auto area = number("S", true), ix = number("Ix", true);
    const auto iy = number("Iy", true), iz = number("Iz", true);
    const auto wy = number("Wy", false), wz = number("Wz", false);
    if (area && ix && iy && iz) {
      s.area = *area, s.torsion_constant = *ix, s.iy = *iy, s.iz = *iz;
      s.wy = wy.value_or(S(0.0)), s.wz = wz.value_or(S(0.0));
      return s;
    }
  }
  return std::nullopt;
}

// Principal inertias [J1, J2, J3] or a tensor [xx, yy, zz, xy, xz, yz]: positive definite and
// satisfying the triangle inequality J_i + J_j >= J_k.
std::optional<Mat3> read_inertia(ObjectReader& r) {
  const Json* v = r.member("inertia", false);
  if (!v) return std::nullopt;
  const Where at = r.at("inertia");
  if (!v->is_array() || (v->size() != 3 && v->size() != 6)) {
    r.error("inertia",
            "expected 3 principal values or 6 tensor components [xx, yy, zz, xy, xz, yz]");
    return std::nullopt;
  }
  std::vector<double> x;
  for (size_t i = 0; i < v->size(); ++i) {
    const auto n = read_number((*v)[i], at / i, r.diagnostics());
    if (!n) return std::nullopt;
    x.push_back(*n);
  }
  Mat3 j = Mat3::Zero();
  j.diagonal() << x[0], x[1], x[2];
  if (x.size() == 6) {
    j(0, 1) = j(1, 0) = x[3];
    j(0, 2) = j(2, 0) = x[4];
    j(1, 2) = j(2, 1) = x[5];
  }
  const Vec3 p = Eigen::SelfAdjointEigenSolver<Mat3>(j).eigenvalues();
  if (!(p.minCoeff() > 0.0)) {
    r.error("inertia", x.size() == 3 ? "principal inertias must be > 0"
                                     : "inertia tensor must be positive definite");
    return std::nullopt;
  }
  const double tol = 1e-9 * p.sum();
  if (p(0) + p(1) < p(2) - tol) {
    r.error("inertia", "principal inertias violate the triangle inequality (" + number_text(p(0)) +
                           " + " + number_text(p(1)) + " < " + number_text(p(2)) +
                           "): no rigid body has them");
    return std::nullopt;
  }
  return j;
}

// The inertia read by read_inertia with the numbers at `at` / 0 .. 5 seeded ([xx, yy, zz] or
// [xx, yy, zz, xy, xz, yz]).
template <class S>
Mat3T<S> seeded_inertia(const SceneSpecsT<S>& specs, const Mat3& j, const Where& at, bool tensor) {
  Mat3T<S> out = j.cast<S>();
  for (size_t i = 0; i < 3; ++i) out(i, i) = seeded(specs, j(i, i), at / i);
  if (tensor) {
    const int rows[3] = {0, 0, 1}, cols[3] = {1, 2, 2};
    for (size_t k = 0; k < 3; ++k)
      out(rows[k], cols[k]) = out(cols[k], rows[k]) =
          seeded(specs, j(rows[k], cols[k]), at / (3 + k));
  }
  return out;
}

template <class S>
std::optional<TimeFunctionT<S>> read_time_function(const Json& value, const Where& where,
                                                   Diagnostics& diag, const SceneSpecsT<S>& specs) {
  ObjectReader r(value, where, diag);
  if (!r.is_object()) return std::nullopt;
  using TimeFunction = TimeFunctionT<S>;
  const auto number = [&](const std::string& key, double x) { return seeded(specs, x, r.at(key)); };
  TimeFunction f;
  const auto type =
      r.choice("type", true, {"constant", "step", "ramp", "smooth_ramp", "harmonic", "table"});
  if (!type) {
    r.allow({"at", "from", "to", "frequency", "phase", "t", "v"});
    return std::nullopt;
  }
  if (*type == "constant") return f;
  if (*type == "step") {
    f.type = TimeFunction::Type::kStep;
    f.at = number("at", r.number_or("at", 0.0));
    return f;
  }
  if (*type == "ramp" || *type == "smooth_ramp") {
    f.type = *type == "ramp" ? TimeFunction::Type::kRamp : TimeFunction::Type::kSmoothRamp;
    const auto from = r.number("from", true), to = r.number("to", true);
    if (!from || !to) return std::nullopt;
    if (*to <= *from) {
      r.error("to", "must be greater than \"from\"");
      return std::nullopt;
    }
    f.from = number("from", *from), f.to = number("to", *to);
    return f;
  }
  if (*type == "harmonic") {
    f.type = TimeFunction::Type::kHarmonic;
    const auto freq = r.positive("frequency", true);
    f.phase = number("phase", r.number_or("phase", 0.0));
    if (!freq) return std::nullopt;
    if (*freq > kMaxHarmonicFrequency) {
      // Far beyond any mechanical load, and 2 pi f t would overflow at the top of the range.
      r.error("frequency", "must be at most 1e12 Hz");
      return std::nullopt;
    }
    f.frequency = number("frequency", *freq);
    return f;
  }
  f.type = TimeFunction::Type::kTable;
  const auto t = r.numbers("t", true, -1), v = r.numbers("v", true, -1);
  if (!t || !v) return std::nullopt;
  if (t->size() != v->size()) {
    r.error("v", "must have as many values as \"t\" (" + std::to_string(t->size()) + ")");
    return std::nullopt;
  }
  for (size_t i = 1; i < t->size(); ++i)
    if (!((*t)[i] > (*t)[i - 1])) {
      diag.error(where.file, (where / "t" / i).pointer, "times must be strictly increasing");
      return std::nullopt;
    }
  for (size_t i = 0; i < t->size(); ++i) {
    f.t.push_back(seeded(specs, (*t)[i], r.at("t") / i));
    f.v.push_back(seeded(specs, (*v)[i], r.at("v") / i));
  }
  return f;
}

// Resolves a body name ("ground" or a scene body).
template <class S>
std::optional<int> body_ref(ObjectReader& r, const std::string& key, const SceneSpecsT<S>& specs) {
  const auto name = r.string(key, true);
  if (!name) return std::nullopt;
  const auto it = specs.body_index.find(*name);
  if (it == specs.body_index.end()) {
    if (!specs.bodies_incomplete) r.error(key, "unknown body \"" + *name + "\"");
    return std::nullopt;
  }
  return it->second;
}

// Takes `name` for an element (beams, rails and joints share one name space); false, reported
// at "name", when it is empty or taken.
template <class S>
bool claim_element_name(ObjectReader& r, const std::string& name, SceneSpecsT<S>& specs) {
  if (name.empty()) {
    r.error("name", "must not be empty");
    return false;
  }
  if (!specs.element_names.insert(name).second) {
    r.error("name",
            "duplicate element name \"" + name + "\" (beams, rails and joints share names)");
    return false;
  }
  return true;
}

// Whether an optional member is present but not of the expected kind (reported by the caller).
bool unusable(ObjectReader& scene, const std::string& key, bool array) {
  const Json* v = scene.member(key, false);
  return v && (array ? !v->is_array() : !v->is_object());
}

}  // namespace

template <class S>
void read_materials(ObjectReader& scene, SceneSpecsT<S>& specs) {
  specs.materials_incomplete = unusable(scene, "materials", false);
  for_each_member(scene, "materials", [&](const std::string& name, const Json& v, const Where& at) {
    ObjectReader r(v, at, scene.diagnostics());
    const auto e = r.positive("E", true), g = r.positive("G", true);
    const auto rho = r.positive("density", false, true);
    const bool density_ok = rho || !r.member("density", false);
    if (e && g && density_ok)
      specs.materials[name] = {seeded(specs, *e, r.at("E")), seeded(specs, *g, r.at("G")),
                               seeded(specs, rho.value_or(0.0), r.at("density"))};
    else
      specs.invalid_materials.insert(name);
  });
}

template <class S>
void read_sections(ObjectReader& scene, SceneSpecsT<S>& specs) {
  specs.sections_incomplete = unusable(scene, "sections", false);
  for_each_member(scene, "sections", [&](const std::string& name, const Json& v, const Where& at) {
    ObjectReader r(v, at, scene.diagnostics());
    std::optional<SectionPropertiesT<S>> s;
    if (r.is_object()) s = read_section(r, specs);
    // Dimensions each finite can give properties that are not (a width of 1e200: S = inf, or
    // 1e-200: S = 0).
    const auto in_range = [](const S& x) { return std::isfinite(value_of(x)) && x > 0.0; };
    if (s && !(in_range(s->area) && in_range(s->torsion_constant) && in_range(s->iy) &&
               in_range(s->iz))) {
      scene.diagnostics().error(
          at.file, at.pointer,
          "the section's properties are out of the range of double precision (S = " +
              number_text(value_of(s->area)) +
              ", Ix = " + number_text(value_of(s->torsion_constant)) + ", Iy = " +
              number_text(value_of(s->iy)) + ", Iz = " + number_text(value_of(s->iz)) + ")");
      s.reset();
    }
    if (s)
      specs.sections[name] = *s;
    else
      specs.invalid_sections.insert(name);
  });
}

// A driven body's "motion": {"velocity": [..], "velocity_time": {..}, "angular_velocity": [..],
// "angular_velocity_time": {..}} (core/model/motion.hpp); the time functions default to constant.
template <class S>
std::optional<PrescribedMotion> read_motion(const Json& value, const Where& where,
                                            Diagnostics& diag, const SceneSpecsT<S>& specs) {
  ObjectReader r(value, where, diag);
  if (!r.is_object()) return std::nullopt;
  PrescribedMotion m;
  const auto velocity = r.vec3("velocity", false);
  const auto angular_velocity = r.vec3("angular_velocity", false);
  bool ok = true;
  const auto time = [&](const std::string& key, TimeFunction& out) {
    const Json* t = r.member(key, false);
    if (!t) return;
    const std::optional<TimeFunctionT<S>> f = read_time_function(*t, where / key, diag, specs);
    if (!f) {
      ok = false;
      return;
    }
    out.type = static_cast<TimeFunction::Type>(f->type);
    out.at = value_of(f->at), out.from = value_of(f->from), out.to = value_of(f->to);
    out.frequency = value_of(f->frequency), out.phase = value_of(f->phase);
    for (const S& x : f->t) out.t.push_back(value_of(x));
    for (const S& x : f->v) out.v.push_back(value_of(x));
  };
  time("velocity_time", m.velocity_time);
  time("angular_velocity_time", m.angular_velocity_time);
  if (!r.member("velocity", false) && !r.member("angular_velocity", false)) {
    diag.error(where.file, where.pointer,
               "a motion needs \"velocity\" or \"angular_velocity\" (or both)");
    return std::nullopt;
  }
  if ((r.member("velocity", false) && !velocity) ||
      (r.member("angular_velocity", false) && !angular_velocity) || !ok)
    return std::nullopt;
  if (velocity) m.velocity = *velocity;
  if (angular_velocity) m.angular_velocity = *angular_velocity;
  return m;
}

template <class S>
void read_bodies(ObjectReader& scene, SceneSpecsT<S>& specs) {
  BodySpecT<S> ground;
  ground.name = "ground";
  ground.fixed = true;
  specs.bodies.push_back(ground);
  specs.body_index["ground"] = 0;
  Diagnostics& diag = scene.diagnostics();
  specs.bodies_incomplete = unusable(scene, "bodies", true);
  for_each_entry(scene, "bodies", [&](const Json& v, const Where& at) {
    ObjectReader r(v, at, diag);
    if (!r.is_object()) {
      specs.bodies_incomplete = true;
      return;
    }
    BodySpecT<S> b;
    b.where = at;
    const auto name = r.string("name", true);
    b.fixed = r.boolean("fixed", false).value_or(false);
    b.mass = seeded(specs, r.positive("mass", false), r.at("mass"));
    if (const auto j = read_inertia(r)) {
      const Json* given = r.member("inertia", false);
      b.inertia = seeded_inertia(specs, *j, r.at("inertia"), given && given->size() == 6);
    }
    const auto position = r.vec3("position", true);
    const auto orientation = r.numbers("orientation", false, 4);
    b.velocity = seeded(specs, r.vec3("velocity", false).value_or(Vec3::Zero()), r.at("velocity"));
    b.angular_velocity = seeded(specs, r.vec3("angular_velocity", false).value_or(Vec3::Zero()),
                                r.at("angular_velocity"));
    if (position) b.position = seeded(specs, *position, r.at("position"));
    if (orientation) {
      const Vec4 q((*orientation)[0], (*orientation)[1], (*orientation)[2], (*orientation)[3]);
      if (std::abs(q.norm() - 1.0) > 1e-3) {
        r.error("orientation",
                "Euler parameters must have unit norm (norm is " + number_text(q.norm()) + ")");
      } else {
        Vec4T<S> qs;
        for (size_t i = 0; i < 4; ++i) qs(i) = seeded(specs, q(i), r.at("orientation") / i);
        b.orientation = qs / qs.norm();
      }
    }
    // Only when the other one is absent (an invalid one was reported already).
    if (const Json* motion = r.member("motion", false)) {
      if (const auto m = read_motion(*motion, r.at("motion"), diag, specs)) {
        b.driven = true;
        b.motion = *m;
      }
      if (b.fixed) r.error("fixed", "a body with a \"motion\" is driven, not fixed: drop one");
      for (const char* key : {"velocity", "angular_velocity"})
        if (r.member(key, false))
          r.error(key, std::string("a driven body's velocities are its \"motion\"'s: drop \"") +
                           key + "\"");
      b.fixed = true;  // no analysis solves for its motion
    }
    const bool has_mass = r.member("mass", false), has_inertia = r.member("inertia", false);
    if (b.mass && !has_inertia && !b.fixed)
      r.error("inertia", "a free body with a mass needs an inertia");
    if (b.inertia && !has_mass && !b.fixed)
      r.error("mass", "a free body with an inertia needs a mass");
    if (!name) {
      specs.bodies_incomplete = true;
      return;
    }
    b.name = *name;
    if (b.name.empty()) {
      specs.bodies_incomplete = true;
      r.error("name", "must not be empty");
    } else if (specs.body_index.count(b.name)) {
      r.error("name", b.name == "ground"
                          ? "\"ground\" is the implicit fixed body; choose another name"
                          : "duplicate body name \"" + b.name + "\"");
    } else {
      specs.body_index[b.name] = static_cast<int>(specs.bodies.size());
      specs.bodies.push_back(b);
    }
  });
}

std::optional<Mat3> element_frame(const Vec3& p1, const Vec3& p2, const Vec3& p3,
                                  const Where& where, Diagnostics& diag) {
  const Vec3 d = p2 - p1;
  // Beyond ~1e154 m squares overflow: the points would otherwise be taken to coincide.
  if (!std::isfinite(d.squaredNorm()) || !std::isfinite((p3 - p1).squaredNorm())) {
    diag.error(where.file, where.pointer,
               "the points are too far apart for double precision (their squared distances "
               "overflow)");
    return std::nullopt;
  }
  const double length = d.norm();
  const double scale = std::max({p1.stableNorm(), p2.stableNorm(), p3.stableNorm()});
  if (!(length > 1e-12 * scale) || length == 0.0) {
    diag.error(where.file, (where / "point2").pointer, "point1 and point2 coincide");
    return std::nullopt;
  }
  const Vec3 x = d / length;
  const Vec3 off = p3 - p1;
  const Vec3 y = off - off.dot(x) * x;
  if (!(y.norm() > 1e-9 * std::max(length, off.norm()))) {
    diag.error(where.file, (where / "point3").pointer,
               "point3 lies on the axis through point1 and point2; it must be off the axis to "
               "fix the section's y axis");
    return std::nullopt;
  }
  Mat3 frame;
  frame.col(0) = x;
  frame.col(1) = y.normalized();
  frame.col(2) = x.cross(frame.col(1));
  return frame;
}

template <class S>
void read_elements(ObjectReader& scene, SceneSpecsT<S>& specs, bool rails) {
  Diagnostics& diag = scene.diagnostics();
  for_each_entry(scene, rails ? "rails" : "beams", [&](const Json& v, const Where& at) {
    ObjectReader r(v, at, diag);
    if (!r.is_object()) return;
    ElementSpecT<S> e;
    e.where = at;
    e.rail = rails;
    const auto name = r.string("name", true);
    if (rails) {
      const auto type = r.choice("type", true, {"prismatic", "cylindrical"});
      if (type) e.rail_type = *type == "prismatic" ? RailType::kPrismatic : RailType::kCylindrical;
    }
    const auto b1 = body_ref(r, "body1", specs), b2 = body_ref(r, "body2", specs);
    const auto p1 = r.vec3("point1", true), p2 = r.vec3("point2", true);
    const auto p3 = r.vec3("point3", true);
    const auto material = r.string("material", true), section = r.string("section", true);
    e.damping = seeded(specs, r.positive("damping", false, true).value_or(0.0), r.at("damping"));
    const auto form = r.choice("formulation", false, {"energy", "paper"});
    if (form && *form == "paper") e.formulation = Formulation::kPaper;
    std::optional<long> segments;
    if (const Json* m = r.member("segments", false); m && m->is_string()) {
      if (*m == "auto")
        e.auto_segments = true;
      else
        r.error("segments",
                "expected an integer >= 0 or \"auto\", got \"" + m->get<std::string>() + "\"");
    } else {
      segments = r.integer("segments", false, 0);
    }
    if (segments && *segments > kMaxSegments) {
      r.error("segments", "at most " + std::to_string(kMaxSegments) + " segments");
      e.segments = 0;
    } else if (segments && specs.n_segments + *segments > kMaxSegments) {
      // Reported once, at the beam that crosses the limit.
      if (specs.n_segments <= kMaxSegments)
        r.error("segments", "at most " + std::to_string(kMaxSegments) +
                                " segments in a scene, all beams together (the beams before "
                                "this one have " +
                                std::to_string(specs.n_segments) + ")");
      specs.n_segments = kMaxSegments + 1;
      e.segments = 0;
    } else {
      e.segments = segments.value_or(0);
    }
    if (rails) {
      e.min_length = seeded(specs, r.positive("min_length", false), r.at("min_length"));
      auto travel = r.numbers("travel", false, 2);
      if (travel && !((*travel)[0] < (*travel)[1])) {
        r.error("travel", "must be [min, max] with min < max (metres along the rail from point 1)");
        travel.reset();
      } else if (travel && p1 && p2) {
        const double l0 = (*p2 - *p1).norm();
        if (!(l0 >= (*travel)[0] && l0 <= (*travel)[1])) {
          char text[160];
          std::snprintf(text, sizeof text,
                        "the carriage starts at %.6g m from point 1, outside its travel", l0);
          r.error("travel", text);
          travel.reset();
        }
      }
      if (travel)
        e.travel = std::vector<S>{seeded(specs, (*travel)[0], r.at("travel") / 0),
                                  seeded(specs, (*travel)[1], r.at("travel") / 1)};
    }
    bool ok = name && b1 && b2 && p1 && p2 && p3 && material && section;
    if (name && !claim_element_name(r, *name, specs)) ok = false;
    // A material or section declared but invalid was reported where it is declared.
    if (material && !specs.materials.count(*material)) {
      if (!specs.invalid_materials.count(*material) && !specs.materials_incomplete)
        r.error("material", "unknown material \"" + *material + "\"");
      ok = false;
    }
    if (section && !specs.sections.count(*section)) {
      if (!specs.invalid_sections.count(*section) && !specs.sections_incomplete)
        r.error("section", "unknown section \"" + *section + "\"");
      ok = false;
    }
    if (b1 && b2 && *b1 == *b2) {
      r.error("body2", "an element must join two different bodies");
      ok = false;
    }
    if (p1 && p2 && p3 && !element_frame(*p1, *p2, *p3, at, diag)) ok = false;
    if (rails && (e.segments > 0 || e.auto_segments)) {
      r.error("segments", "rails cannot be segmented: the carriage slides along them");
      ok = false;
    }
    if (ok && (e.segments > 0 || e.auto_segments) && specs.materials.at(*material).density <= 0.0) {
      r.error("segments", "a segmented beam needs a material with a density > 0");
      ok = false;
    }
    if (!ok) return;
    e.name = *name, e.body1 = *b1, e.body2 = *b2;
    e.p1 = seeded(specs, *p1, r.at("point1"));
    e.p2 = seeded(specs, *p2, r.at("point2"));
    e.p3 = seeded(specs, *p3, r.at("point3"));
    e.material = specs.materials.at(*material);
    e.section = specs.sections.at(*section);
    e.material_name = *material;
    e.section_name = *section;
    specs.n_segments += e.segments;
    specs.elements.push_back(e);
  });
}

template <class S>
void read_loads(ObjectReader& scene, SceneSpecsT<S>& specs) {
  Diagnostics& diag = scene.diagnostics();
  for_each_entry(scene, "loads", [&](const Json& v, const Where& at) {
    ObjectReader r(v, at, diag);
    if (!r.is_object()) return;
    LoadT<S> load;
    const auto type = r.choice("type", true, {"force", "torque"});
    if (!type) r.allow({"point", "case", "follows"});
    const auto body = body_ref(r, "body", specs);
    std::optional<Vec3> point;
    if (type && *type == "force") point = r.vec3("point", false);
    const auto value = r.vec3("value", true);
    const auto load_case = r.string("case", false);
    const auto follows = r.boolean("follows", false);
    const bool follows_bad = !follows && v.contains("follows");  // reported by r.boolean
    if (load_case && load_case->empty())
      r.error("case", "must not be empty (omit it for a load of every analysis)");
    std::optional<TimeFunctionT<S>> time = TimeFunctionT<S>{};
    if (const Json* t = r.member("time", false))
      time = read_time_function(*t, at / "time", diag, specs);
    if (body && specs.bodies[*body].fixed) {
      r.error("body", "body \"" + specs.bodies[*body].name + "\" is " +
                          (specs.bodies[*body].driven ? "driven by its \"motion\"" : "fixed") +
                          ": a load on it does nothing");
      return;
    }
    if (!type || !body || !value || !time || follows_bad || (load_case && load_case->empty()))
      return;
    if (load_case) {
      load.load_case = *load_case;
      if (std::find(specs.load_cases.begin(), specs.load_cases.end(), *load_case) ==
          specs.load_cases.end())
        specs.load_cases.push_back(*load_case);
    }
    load.kind = *type == "force" ? LoadKind::kForce : LoadKind::kTorque;
    load.body = *body;
    // A follower load keeps the value given (global axes, initial configuration) in body axes.
    load.follows = follows.value_or(false);
    const Vec3T<S> given = seeded(specs, *value, r.at("value"));
    load.value =
        load.follows
            ? Vec3T<S>(rotation_matrix<S>(specs.bodies[*body].orientation).transpose() * given)
            : given;
    load.time = *time;
    specs.loads.push_back(load);
    specs.load_points.push_back(point ? seeded(specs, *point, r.at("point"))
                                      : specs.bodies[*body].position);
    specs.load_where.push_back(at);
  });
}

template <class S>
void read_joints(ObjectReader& scene, SceneSpecsT<S>& specs) {
  Diagnostics& diag = scene.diagnostics();
  for_each_entry(scene, "joints", [&](const Json& v, const Where& at) {
    ObjectReader r(v, at, diag);
    if (!r.is_object()) return;
    JointSpecT<S> j;
    j.where = at;
    const auto name = r.string("name", true);
    const auto type = r.choice("type", true, {"spherical", "revolute", "fixed"});
    const auto b1 = body_ref(r, "body1", specs), b2 = body_ref(r, "body2", specs);
    const auto point = r.vec3("point", true);
    std::optional<Vec3> axis;
    if (type && *type == "revolute")
      axis = r.vec3("axis", true);
    else
      r.allow({"axis"});
    if (type && *type != "revolute" && v.contains("axis"))
      r.error("axis", "only a revolute joint has an axis");
    const auto compliance = r.positive("relative_compliance", false);
    bool ok = name && type && b1 && b2 && point && (!type || *type != "revolute" || axis);
    if (ok && *type == "revolute" && !(axis->norm() > 0.0 && std::isfinite(axis->norm()))) {
      r.error("axis", "must be a non-zero direction");
      ok = false;
    }
    if (compliance && !(*compliance < 1.0)) {
      r.error("relative_compliance", "must be below 1 (the joint's compliance over the scene's)");
      ok = false;
    }
    if (name && !claim_element_name(r, *name, specs)) ok = false;
    if (b1 && b2 && *b1 == *b2) {
      r.error("body2", "a joint must join two different bodies");
      ok = false;
    }
    if (!ok) return;
    j.name = *name;
    j.type = *type == "spherical"  ? JointType::kSpherical
             : *type == "revolute" ? JointType::kRevolute
                                   : JointType::kFixed;
    j.body1 = *b1, j.body2 = *b2, j.point = seeded(specs, *point, r.at("point"));
    if (axis) j.axis = seeded(specs, *axis, r.at("axis")).normalized();
    if (compliance) j.relative_compliance = seeded(specs, *compliance, r.at("relative_compliance"));
    specs.joints.push_back(j);
  });
}

#define BEAMRAIL_READERS(S)                                             \
  template void read_materials<S>(ObjectReader&, SceneSpecsT<S>&);      \
  template void read_sections<S>(ObjectReader&, SceneSpecsT<S>&);       \
  template void read_bodies<S>(ObjectReader&, SceneSpecsT<S>&);         \
  template void read_elements<S>(ObjectReader&, SceneSpecsT<S>&, bool); \
  template void read_loads<S>(ObjectReader&, SceneSpecsT<S>&);          \
  template void read_joints<S>(ObjectReader&, SceneSpecsT<S>&);
BEAMRAIL_READERS(double)
BEAMRAIL_READERS(HyperDual)
#undef BEAMRAIL_READERS

}  // namespace beamrail
