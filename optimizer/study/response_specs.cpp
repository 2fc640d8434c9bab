// Reading the named "responses" of a study.
#include <algorithm>
#include <iterator>

#include "core/analysis/modal_analysis.hpp"
#include "core/model/element_kinds.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

const std::vector<std::string> kResponseQuantities = {
    "frequency",  "displacement",  "rotation",        "peak_displacement", "mass",
    "max_stress", "element_force", "buckling_factor", "expression",        "joint_gap"};

namespace {

const std::vector<std::string> kComponents = {"fx", "fy", "fz", "mx", "my", "mz"};
const std::vector<std::string> kDirections(std::begin(kDirectionNames), std::end(kDirectionNames));

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

// Resolves an element name: a rail, a joint, a beam, or a segmented beam (its first or last
// segment).
std::optional<ElementEnd> element_named(ObjectReader& r, const Model* model, int end) {
  const auto name = r.string("element", true);
  if (!name || !model) return std::nullopt;
  if (const std::optional<ElementRef> found = find_element(*model, *name, end))
    return ElementEnd{*found, end};
  r.error("element", "unknown element \"" + *name + "\"");
  return std::nullopt;
}

// A list of names under `key` (nullopt when absent; reported when not a non-empty array of
// strings).
std::optional<std::vector<std::string>> name_list(ObjectReader& r, const std::string& key,
                                                  bool* ok) {
  const Json* list = r.member(key, false);
  if (!list) return std::nullopt;
  std::vector<std::string> names;
  if (!list->is_array() || list->empty()) {
    r.error(key, "expected a non-empty array of names");
    *ok = false;
    return names;
  }
  for (size_t i = 0; i < list->size(); ++i) {
    if (!(*list)[i].is_string()) {
      const Where at = r.at(key) / i;
      r.diagnostics().error(at.file, at.pointer, "expected a name");
      *ok = false;
      continue;
    }
    names.push_back((*list)[i].get<std::string>());
  }
  return names;
}

// mass: "bodies" (scene bodies' declared masses) and "elements" (beams and rails, rho S l) to
// count; without either, the whole structure.
bool read_mass_subset(ObjectReader& r, const Model* model, ResponseSpec& s) {
  bool ok = true;
  const auto bodies = name_list(r, "bodies", &ok);
  const auto elements = name_list(r, "elements", &ok);
  if (!bodies && !elements) return ok;
  s.subset = true;
  if (!model || !ok) return ok;
  for (size_t n = 0; bodies && n < bodies->size(); ++n) {
    int found = -1;
    for (size_t i = 0; i < model->bodies.size(); ++i)
      if (model->bodies[i].name == (*bodies)[n] && !model->bodies[i].generated)
        found = static_cast<int>(i);
    const Where at = r.at("bodies") / n;
    if (found < 0)
      r.diagnostics().error(at.file, at.pointer, "unknown body \"" + (*bodies)[n] + "\"");
    else
      s.mass_bodies.push_back(found);
    ok = ok && found >= 0;
  }
  for (size_t n = 0; elements && n < elements->size(); ++n) {
    const std::string& name = (*elements)[n];
    bool found = false;
    for (size_t i = 0; i < model->beams.size(); ++i)
      if (model->beams[i].group == name) s.mass_beams.push_back(static_cast<int>(i)), found = true;
    for (size_t i = 0; i < model->rails.size(); ++i)
      if (model->rails[i].name == name) s.mass_rails.push_back(static_cast<int>(i)), found = true;
    if (!found) {
      const Where at = r.at("elements") / n;
      r.diagnostics().error(at.file, at.pointer, "unknown beam or rail \"" + name + "\"");
      ok = false;
    }
  }
  return ok;
}

// Whether every entry of the study's "analyses" was read (then a name not among them is unknown).
bool all_analyses_read(const Study& study) {
  const auto list = study.document.find("analyses");
  return list != study.document.end() && list->is_array() && list->size() == study.analyses.size();
}

// The analysis a response reads: the one its "analysis" names, or the only one of `type`.
// Reports a name that is unknown or of another type, a missing analysis, and an ambiguous choice.
std::optional<int> analysis_for(ObjectReader& r, const Study& study, AnalysisSpec::Type type,
                                const std::string& quantity) {
  const std::string wanted = type_name(type);
  if (const Json* given = r.member("analysis", false)) {
    if (!given->is_string()) {
      r.error("analysis", "expected the name of an analysis, got " + json_type_name(*given));
      return std::nullopt;
    }
    const std::string name = given->get<std::string>();
    const int k = find_analysis(study, name);
    if (k < 0) {
      if (!all_analyses_read(study)) return std::nullopt;  // its entry had errors
      std::string known;
      for (const AnalysisSpec& a : study.analyses)
        known += (known.empty() ? "\"" : ", \"") + a.name + "\"";
      r.error("analysis",
              "unknown analysis \"" + name + "\" (the study's analyses: " + known + ")");
      return std::nullopt;
    }
    if (study.analyses[k].type != type) {
      r.error("analysis", "analysis \"" + name + "\" is a " + type_name(study.analyses[k].type) +
                              " analysis; \"" + quantity + "\" needs a " + wanted + " analysis");
      return std::nullopt;
    }
    return k;
  }
  std::vector<int> candidates;
  for (size_t i = 0; i < study.analyses.size(); ++i)
    if (study.analyses[i].type == type) candidates.push_back(static_cast<int>(i));
  if (candidates.size() == 1) return candidates[0];
  if (candidates.size() > 1) {
    std::string names;
    for (int k : candidates)
      names += (names.empty() ? "\"" : ", \"") + study.analyses[k].name + "\"";
    r.error("analysis", "the study has " + std::to_string(candidates.size()) + " " + wanted +
                            " analyses (" + names + "): name the one \"" + quantity +
                            "\" reads with \"analysis\"");
    return std::nullopt;
  }
  if (lacks_analysis(study.document, wanted))
    r.error("quantity", "\"" + quantity + "\" needs a " + wanted + " analysis in \"analyses\"");
  return std::nullopt;
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
    r.allow({"body", "point", "direction", "axis", "mode", "element", "component", "end",
             "elements", "analysis", "bodies", "expression", "track", "dominant", "joint"});
    return std::nullopt;
  }
  if (*q == "mass") {
    s.quantity = ResponseSpec::Quantity::kMass;
    return read_mass_subset(r, model, s) ? std::optional<ResponseSpec>(s) : std::nullopt;
  }
  if (*q == "expression") {
    s.quantity = ResponseSpec::Quantity::kExpression;
    const auto text = r.string("expression", true);
    if (!text) return std::nullopt;
    if (text->empty() || text->size() > 10000) {
      r.error("expression", "expected a formula of 1 to 10000 characters");
      return std::nullopt;
    }
    s.expression = *text;
    return s;  // its names are checked once every response is read (resolve_expressions)
  }
  if (*q == "frequency" || *q == "buckling_factor") {
    const bool frequency = *q == "frequency";
    s.quantity =
        frequency ? ResponseSpec::Quantity::kFrequency : ResponseSpec::Quantity::kBucklingFactor;
    const auto analysis = analysis_for(
        r, study, frequency ? AnalysisSpec::Type::kModal : AnalysisSpec::Type::kBuckling, *q);
    if (frequency) {
      if (const auto track = r.boolean("track", false)) s.track = *track;
      if (const auto d = r.choice("dominant", false, kDirections)) {
        s.dominant = static_cast<int>(std::find(kDirections.begin(), kDirections.end(), *d) -
                                      kDirections.begin());
        if (r.member("mode", false)) {
          r.error("dominant", "give either \"mode\" or \"dominant\"");
          return std::nullopt;
        }
        if (s.track) {
          r.error("track", "a mode chosen by its dominant direction is not tracked by shape");
          return std::nullopt;
        }
        if (!analysis) return std::nullopt;
        s.analysis = *analysis;
        return s;
      }
    }
    const auto mode = r.integer("mode", true, 1);
    if (!mode || !analysis) return std::nullopt;
    s.analysis = *analysis;
    s.mode = static_cast<int>(std::min(*mode, 1000000L));
    const AnalysisSpec& a = study.analyses[*analysis];
    const int computed = frequency ? a.modal.modes : a.buckling.modes;
    if (s.mode > computed)
      r.error("mode", "the " + std::string(type_name(a.type)) + " analysis \"" + a.name +
                          "\" computes " + std::to_string(computed) +
                          " modes; raise its \"modes\" to at least " + std::to_string(s.mode));
    return s;
  }
  if (*q == "displacement" || *q == "peak_displacement") {
    s.quantity = *q == "displacement" ? ResponseSpec::Quantity::kDisplacement
                                      : ResponseSpec::Quantity::kPeakDisplacement;
    const auto analysis = analysis_for(
        r, study,
        *q == "displacement" ? AnalysisSpec::Type::kStatic : AnalysisSpec::Type::kTransient, *q);
    const auto body = body_named(r, "body", model);
    const auto point = r.vec3("point", false);
    const auto direction = unit_vector(r, "direction");
    std::optional<int> relative_to;
    if (r.member("relative_to", false)) {
      if (s.quantity == ResponseSpec::Quantity::kPeakDisplacement) {
        relative_to = body_named(r, "relative_to", model);
        if (!relative_to) return std::nullopt;
      } else {
        r.error("relative_to", "applies to peak_displacement only");
        return std::nullopt;
      }
    }
    if (!body || !direction || !analysis) return std::nullopt;
    s.relative_to = relative_to.value_or(-1);
    s.analysis = *analysis;
    s.body = *body;
    s.point = point.value_or(model->bodies[*body].position);
    s.point_given = point.has_value();
    s.direction = *direction;
    return s;
  }
  if (*q == "rotation") {
    s.quantity = ResponseSpec::Quantity::kRotation;
    const auto analysis = analysis_for(r, study, AnalysisSpec::Type::kStatic, *q);
    const auto body = body_named(r, "body", model);
    const auto axis = unit_vector(r, "axis");
    if (!body || !axis || !analysis) return std::nullopt;
    s.analysis = *analysis;
    s.body = *body;
    s.direction = *axis;
    return s;
  }
  if (*q == "element_force") {
    s.quantity = ResponseSpec::Quantity::kElementForce;
    const auto analysis = analysis_for(r, study, AnalysisSpec::Type::kStatic, *q);
    const auto component = r.choice("component", true, kComponents);
    const auto end = r.integer("end", false, 1);
    if (end && *end > 2) r.error("end", "must be 1 or 2");
    const auto element = element_named(r, model, static_cast<int>(end.value_or(1)));
    if (!component || !element || (end && *end > 2) || !analysis) return std::nullopt;
    s.analysis = *analysis;
    s.component = static_cast<int>(std::find(kComponents.begin(), kComponents.end(), *component) -
                                   kComponents.begin());
    s.element = *element;
    return s;
  }
  if (*q == "joint_gap") {
    s.quantity = ResponseSpec::Quantity::kJointGap;
    const auto analysis = analysis_for(r, study, AnalysisSpec::Type::kStatic, *q);
    const auto joint = r.string("joint", true);
    if (!joint || !analysis || !model) return std::nullopt;
    if (const int index = index_named(model->joints, *joint); index >= 0) {
      s.analysis = *analysis;
      s.joint = index;
      return s;
    }
    r.error("joint", "unknown joint \"" + *joint + "\"");
    return std::nullopt;
  }
  // max_stress
  s.quantity = ResponseSpec::Quantity::kMaxStress;
  const auto analysis = analysis_for(r, study, AnalysisSpec::Type::kStatic, *q);
  if (analysis) s.analysis = *analysis;
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
  if (!model || !analysis) return std::nullopt;
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
