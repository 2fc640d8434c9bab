// Reading the named "responses" of a study.
#include <algorithm>

#include "optimizer/study.hpp"

namespace beamrail {

const std::vector<std::string> kResponseQuantities = {
    "frequency", "displacement", "rotation",     "peak_displacement",
    "mass",      "max_stress",   "element_force"};

namespace {

const std::vector<std::string> kComponents = {"fx", "fy", "fz", "mx", "my", "mz"};

// Whether the study's list of analyses certainly has none of this type. A missing or malformed
// list, or an entry whose type is missing or wrong, was reported already: then a response that
// needs the analysis does not add a second message.
bool lacks_analysis(const Json& document, const std::string& type) {
  const auto list = document.find("analyses");
  if (list == document.end() || !list->is_array() || list->empty()) return false;
  for (const Json& a : *list) {
    if (!a.is_object()) return false;
    const auto t = a.find("type");
    if (t == a.end() || !t->is_string()) return false;
    const std::string name = t->get<std::string>();
    if (name == type) return false;
    if (std::find(kAnalysisTypes.begin(), kAnalysisTypes.end(), name) == kAnalysisTypes.end())
      return false;
  }
  return true;
}

// The index of a named body; without a model (the scene has errors) only the name is checked.
std::optional<int> body_named(ObjectReader& r, const std::string& key, const Model* model) {
  const auto name = r.string(key, true);
  if (!name || !model) return std::nullopt;
  for (size_t i = 0; i < model->bodies.size(); ++i)
    if (model->bodies[i].name == *name && !model->bodies[i].generated) return static_cast<int>(i);
  r.error(key, "unknown body \"" + *name + "\"");
  return std::nullopt;
}

// A unit direction (non-zero vector) under `key`.
std::optional<Vec3> unit_vector(ObjectReader& r, const std::string& key) {
  const auto v = r.vec3(key, true);
  if (!v) return std::nullopt;
  if (!(v->norm() > 0.0)) {
    r.error(key, "must not be the zero vector");
    return std::nullopt;
  }
  return v->normalized();
}

// Resolves an element name: a rail, a beam, or a segmented beam (its first or last segment).
std::optional<ElementEnd> element_named(ObjectReader& r, const Model* model, int end) {
  const auto name = r.string("element", true);
  if (!name || !model) return std::nullopt;
  for (size_t i = 0; i < model->rails.size(); ++i)
    if (model->rails[i].name == *name) return ElementEnd{true, static_cast<int>(i), end};
  int found = -1;
  for (size_t i = 0; i < model->beams.size(); ++i) {
    const Beam& b = model->beams[i];
    if (b.group != *name) continue;
    // The segment that holds the requested end of the scene beam.
    if (found < 0 || (end == 2 && b.segment > model->beams[found].segment))
      found = static_cast<int>(i);
    if (end == 1 && b.segment <= 1) found = static_cast<int>(i);
  }
  if (found >= 0) return ElementEnd{false, found, end};
  r.error("element", "unknown element \"" + *name + "\"");
  return std::nullopt;
}

void require(ObjectReader& r, const Study& study, const std::string& analysis,
             const std::string& quantity) {
  if (lacks_analysis(study.document, analysis))
    r.error("quantity", "\"" + quantity + "\" needs a " + analysis + " analysis in \"analyses\"");
}

}  // namespace

std::optional<ResponseSpec> read_response(const std::string& name, const Json& value,
                                          const Where& where, const Study& study,
                                          const Model* model, Diagnostics& diag) {
  ObjectReader r(value, where, diag);
  if (!r.is_object()) return std::nullopt;
  ResponseSpec s;
  s.name = name;
  s.where = where;
  const auto q = r.choice("quantity", true, kResponseQuantities);
  if (!q) {
    r.allow(
        {"body", "point", "direction", "axis", "mode", "element", "component", "end", "elements"});
    return std::nullopt;
  }
  if (*q == "mass") {
    s.quantity = ResponseSpec::Quantity::kMass;
    return s;
  }
  if (*q == "frequency") {
    s.quantity = ResponseSpec::Quantity::kFrequency;
    require(r, study, "modal", *q);
    const auto mode = r.integer("mode", true, 1);
    if (!mode) return std::nullopt;
    s.mode = static_cast<int>(std::min(*mode, 1000000L));
    const int modal = find_analysis(study, AnalysisSpec::Type::kModal);
    if (modal >= 0 && s.mode > study.analyses[modal].modal.modes)
      r.error("mode", "the modal analysis computes " +
                          std::to_string(study.analyses[modal].modal.modes) +
                          " modes; raise its \"modes\" to at least " + std::to_string(s.mode));
    return s;
  }
  if (*q == "displacement" || *q == "peak_displacement") {
    s.quantity = *q == "displacement" ? ResponseSpec::Quantity::kDisplacement
                                      : ResponseSpec::Quantity::kPeakDisplacement;
    require(r, study, *q == "displacement" ? "static" : "transient", *q);
    const auto body = body_named(r, "body", model);
    const auto point = r.vec3("point", false);
    const auto direction = unit_vector(r, "direction");
    if (!body || !direction) return std::nullopt;
    s.body = *body;
    s.point = point.value_or(model->bodies[*body].position);
    s.direction = *direction;
    return s;
  }
  if (*q == "rotation") {
    s.quantity = ResponseSpec::Quantity::kRotation;
    require(r, study, "static", *q);
    const auto body = body_named(r, "body", model);
    const auto axis = unit_vector(r, "axis");
    if (!body || !axis) return std::nullopt;
    s.body = *body;
    s.direction = *axis;
    return s;
  }
  if (*q == "element_force") {
    s.quantity = ResponseSpec::Quantity::kElementForce;
    require(r, study, "static", *q);
    const auto component = r.choice("component", true, kComponents);
    const auto end = r.integer("end", false, 1);
    if (end && *end > 2) r.error("end", "must be 1 or 2");
    const auto element = element_named(r, model, static_cast<int>(end.value_or(1)));
    if (!component || !element || (end && *end > 2)) return std::nullopt;
    s.component = static_cast<int>(std::find(kComponents.begin(), kComponents.end(), *component) -
                                   kComponents.begin());
    s.element = *element;
    return s;
  }
  // max_stress
  s.quantity = ResponseSpec::Quantity::kMaxStress;
  require(r, study, "static", *q);
  std::vector<std::string> names;
  if (const Json* list = r.member("elements", false)) {
    if (!list->is_array() || list->empty()) {
      r.error("elements", "expected a non-empty array of beam names");
      return std::nullopt;
    }
    for (size_t i = 0; i < list->size(); ++i) {
      if (!(*list)[i].is_string()) {
        diag.error(where.file, (r.at("elements") / i).pointer, "expected a beam name");
        return std::nullopt;
      }
      names.push_back((*list)[i].get<std::string>());
    }
  }
  if (!model) return std::nullopt;
  for (size_t n = 0; n < names.size(); ++n) {
    bool known = false;
    for (const Beam& b : model->beams) known = known || b.group == names[n];
    if (!known)
      diag.error(where.file, (r.at("elements") / n).pointer, "unknown beam \"" + names[n] + "\"");
  }
  for (size_t i = 0; i < model->beams.size(); ++i) {
    const Beam& b = model->beams[i];
    if (!names.empty() && std::find(names.begin(), names.end(), b.group) == names.end()) continue;
    if (!(b.section.wy > 0.0) || !(b.section.wz > 0.0)) {
      r.error("quantity", "beam \"" + b.group +
                              "\" has a custom section without section moduli: give its \"Wy\" "
                              "and \"Wz\"");
      return std::nullopt;
    }
    s.beams.push_back(static_cast<int>(i));
  }
  return s;
}

}  // namespace beamrail
