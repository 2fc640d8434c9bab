#include "optimizer/study.hpp"

#include <algorithm>
#include <cmath>

#include "core/scene/scene_loader.hpp"

namespace beamrail {
namespace {

const std::vector<std::string> kAnalysisTypes = {"transient"};

void read_integrator(const Json& value, const Where& where, Diagnostics& diag,
                     IntegratorOptions& io) {
  ObjectReader r(value, where, diag);
  if (!r.is_object()) return;
  if (const auto m = r.choice("method", false, {"bdf"})) io.method = *m;
  io.rtol = r.positive("rtol", false).value_or(io.rtol);
  io.atol = r.positive("atol", false).value_or(io.atol);
  if (const auto j = r.choice("jacobian", false, {"exact", "fd"}))
    io.jacobian = *j == "exact" ? JacobianKind::kExact : JacobianKind::kFiniteDifference;
  if (const auto s = r.choice("linear_solver", false, {"auto", "dense"}))
    io.linear_solver = *s == "dense" ? LinearSolverKind::kDense : LinearSolverKind::kAuto;
  if (const auto q = r.integer("max_order", false, 1)) {
    if (*q > 5)
      r.error("max_order", "BDF orders go from 1 to 5");
    else
      io.max_order = static_cast<int>(*q);
  }
  io.max_step = r.positive("max_step", false).value_or(0.0);
  io.initial_step = r.positive("initial_step", false).value_or(0.0);
  io.max_steps = r.integer("max_steps", false, 1).value_or(io.max_steps);
}

std::optional<AnalysisSpec> read_analysis(const Json& value, const Where& where,
                                          Diagnostics& diag) {
  ObjectReader r(value, where, diag);
  if (!r.is_object()) return std::nullopt;
  AnalysisSpec a;
  a.where = where;
  const auto type = r.choice("type", true, kAnalysisTypes);
  if (!type) {
    r.allow({"t_end", "output_step", "integrator"});
    return std::nullopt;
  }
  const auto t_end = r.positive("t_end", true);
  const auto step = r.positive("output_step", false);
  if (const Json* i = r.member("integrator", false))
    read_integrator(*i, where / "integrator", diag, a.transient.integrator);
  if (!t_end) return std::nullopt;
  a.transient.t_end = *t_end;
  a.transient.output_step = step.value_or(*t_end / 100.0);
  if (a.transient.output_step > *t_end) {
    r.error("output_step", "must not exceed t_end");
    return std::nullopt;
  }
  if (*t_end / a.transient.output_step > 1e8) {
    r.error("output_step", "more than 1e8 output rows requested");
    return std::nullopt;
  }
  return a;
}

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

std::optional<ResponseSpec> read_response(const std::string& name, const Json& value,
                                          const Where& where, const Study& study,
                                          const Model* model, Diagnostics& diag) {
  ObjectReader r(value, where, diag);
  if (!r.is_object()) return std::nullopt;
  ResponseSpec s;
  s.name = name;
  s.where = where;
  const auto q = r.choice("quantity", true, {"peak_displacement", "mass"});
  if (!q) {
    r.allow({"body", "point", "direction"});
    return std::nullopt;
  }
  if (*q == "mass") {
    s.quantity = ResponseSpec::Quantity::kMass;
    return s;
  }
  s.quantity = ResponseSpec::Quantity::kPeakDisplacement;
  const auto body = body_named(r, "body", model);
  const auto point = r.vec3("point", false);
  const auto direction = r.vec3("direction", true);
  if (lacks_analysis(study.document, "transient"))
    r.error("quantity", "\"peak_displacement\" needs a transient analysis in \"analyses\"");
  if (direction && !(direction->norm() > 0.0)) {
    r.error("direction", "must not be the zero vector");
    return std::nullopt;
  }
  if (!body || !direction) return std::nullopt;
  s.body = *body;
  s.point = point.value_or(model->bodies[*body].position);
  s.direction = direction->normalized();
  return s;
}

}  // namespace

int find_analysis(const Study& study, AnalysisSpec::Type type) {
  for (size_t i = 0; i < study.analyses.size(); ++i)
    if (study.analyses[i].type == type) return static_cast<int>(i);
  return -1;
}

std::optional<Study> load_study(const Json& document, const std::string& file,
                                const std::filesystem::path& directory, Diagnostics& diag) {
  const size_t errors_before = diag.size();
  Study study;
  study.file = file;
  study.directory = directory;
  study.document = document;
  const Where root{file, ""};
  std::optional<Model> model;
  {
    ObjectReader r(document, root, diag);  // reports unknown keys when the block ends
    if (!r.is_object()) return std::nullopt;

    if (const auto name = r.string("name", true)) {
      if (name->empty() || name->find_first_of("/\\") != std::string::npos || *name == "." ||
          *name == "..")
        r.error("name",
                "must be a non-empty name without path separators (it names the output folder)");
      study.name = *name;
    }
    study.description = r.string("description", false).value_or("");

    // The scene: inline, or a path relative to the study file.
    if (const Json* scene = r.member("scene", true)) {
      if (scene->is_string()) {
        // Named in messages as the user can open it from here: relative to the study's folder.
        const std::filesystem::path p = directory / scene->get<std::string>();
        const std::string shown = p.lexically_normal().string();
        std::error_code ec;
        if (scene->get<std::string>().empty()) {
          r.error("scene", "expected the path of a scene file or a scene object, got \"\"");
        } else if (!std::filesystem::exists(p, ec)) {
          r.error("scene", "scene file \"" + shown + "\" not found");
        } else if (const auto j = read_json_file(p.string(), shown, diag)) {
          model = load_scene(*j, {shown, ""}, diag);
          study.document["scene"] = *j;
        }
      } else {
        model = load_scene(*scene, root / "scene", diag);
      }
    }

    if (const Json* list = r.member("analyses", true)) {
      if (!list->is_array() || list->empty()) {
        r.error("analyses", "expected a non-empty array of analyses");
      } else {
        for (size_t i = 0; i < list->size(); ++i)
          if (auto a = read_analysis((*list)[i], root / "analyses" / i, diag))
            study.analyses.push_back(*a);
      }
    }
    if (model) study.model = std::move(*model);

    if (const Json* responses = r.member("responses", false)) {
      if (!responses->is_object()) {
        r.error("responses", "expected an object of named responses");
      } else {
        // Checked even when the scene has errors (body names then go unchecked).
        const Model* m = model ? &study.model : nullptr;
        for (const auto& item : responses->items())
          if (auto s = read_response(item.key(), item.value(), root / "responses" / item.key(),
                                     study, m, diag))
            study.responses.push_back(*s);
      }
    }
    if (r.member("study", false))
      r.error("study", "design studies (sweep, optimize) are not available in this version");
  }

  if (diag.size() > errors_before || !model) return std::nullopt;
  return study;
}

std::optional<Study> load_study_file(const std::string& path, Diagnostics& diag) {
  const size_t errors_before = diag.size();
  const auto document = read_json_file(path, path, diag);
  if (!document) return std::nullopt;
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  // The document is checked even after duplicate keys were reported, so that all problems are
  // listed; it is still rejected.
  auto study = load_study(*document, path, dir, diag);
  if (diag.size() > errors_before) return std::nullopt;
  return study;
}

}  // namespace beamrail
