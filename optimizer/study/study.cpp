#include "optimizer/study/study.hpp"

#include <algorithm>
#include <map>
#include <set>

#include "core/model/element_kinds.hpp"
#include "core/scene/scene_loader.hpp"
#include "optimizer/run/expressions.hpp"

namespace beamrail {

const char* type_name(AnalysisSpec::Type type) {
  switch (type) {
    case AnalysisSpec::Type::kStatic:
      return "static";
    case AnalysisSpec::Type::kModal:
      return "modal";
    case AnalysisSpec::Type::kBuckling:
      return "buckling";
    case AnalysisSpec::Type::kTransient:
      break;
  }
  return "transient";
}

std::string table_file(const AnalysisSpec& analysis, const std::string& table) {
  return analysis.name == type_name(analysis.type) ? table : analysis.name + "." + table;
}

std::string write_segment_counts(Json& document, const std::vector<SegmentChoice>& choices) {
  std::string written;
  const auto scene = document.find("scene");
  if (scene == document.end() || !scene->is_object()) return written;
  bool auto_left = false;
  for (const char* list : {"beams", "rails"}) {
    const auto entries = scene->find(list);
    if (entries == scene->end() || !entries->is_array()) continue;
    for (Json& e : *entries) {
      const auto segments = e.find("segments");
      if (segments == e.end() || !segments->is_string() || *segments != "auto") continue;
      const auto name = e.find("name");
      const auto choice =
          name == e.end() || !name->is_string()
              ? choices.end()
              : std::find_if(choices.begin(), choices.end(),
                             [&](const SegmentChoice& c) { return c.beam == *name; });
      if (choice == choices.end()) {
        auto_left = true;
        continue;
      }
      *segments = choice->segments;
      written +=
          (written.empty() ? "" : ", ") + choice->beam + " " + std::to_string(choice->segments);
    }
  }
  if (!written.empty() && !auto_left) scene->erase("segmentation");
  return written;
}

int find_analysis(const Study& study, AnalysisSpec::Type type) {
  for (size_t i = 0; i < study.analyses.size(); ++i)
    if (study.analyses[i].type == type) return static_cast<int>(i);
  return -1;
}

int find_analysis(const Study& study, const std::string& name) {
  for (size_t i = 0; i < study.analyses.size(); ++i)
    if (study.analyses[i].name == name) return static_cast<int>(i);
  return -1;
}

namespace {

// Default names (the type, numbered when repeated); a name used twice is reported where it is
// given (or at the type of an analysis whose default name another one took).
void name_analyses(Study& study, Diagnostics& diag) {
  std::map<AnalysisSpec::Type, int> count, seen;
  for (const AnalysisSpec& a : study.analyses) ++count[a.type];
  std::set<std::string> given, used;
  for (const AnalysisSpec& a : study.analyses)
    if (!a.name.empty()) given.insert(a.name);
  for (AnalysisSpec& a : study.analyses) {
    const int k = ++seen[a.type];
    const bool explicit_name = !a.name.empty();
    if (!explicit_name)
      a.name = count[a.type] == 1 ? type_name(a.type)
                                  : std::string(type_name(a.type)) + "_" + std::to_string(k);
    if (used.insert(a.name).second && (explicit_name || !given.count(a.name))) continue;
    diag.error(a.where.file, (a.where / (explicit_name ? "name" : "type")).pointer,
               "analysis name \"" + a.name + "\" is used twice" +
                   (explicit_name ? std::string()
                                  : " (it is this analysis's default name): give it a \"name\""));
  }
}

// The load case an analysis names must be one the scene's loads give.
void check_load_cases(const Study& study, Diagnostics& diag) {
  for (const AnalysisSpec& a : study.analyses) {
    if (a.load_case.empty()) continue;
    const auto& cases = study.model.load_cases;
    if (std::find(cases.begin(), cases.end(), a.load_case) != cases.end()) continue;
    std::string known;
    for (const std::string& c : cases) known += (known.empty() ? "\"" : ", \"") + c + "\"";
    diag.error(a.where.file, (a.where / "load_case").pointer,
               "no load has the case \"" + a.load_case + "\"" +
                   (known.empty() ? std::string(" (no load of the scene gives a \"case\")")
                                  : " (the loads' cases: " + known + ")"));
  }
}

// A modal analysis about the static equilibrium of a load case with harmonic loads, which have no
// final value, linearizes about the equilibrium of a static analysis of that case listed in the
// study (which gives their "time"); without one the default equilibrium would evaluate them at
// t = infinity.
void check_modal_equilibria(const Study& study, Diagnostics& diag) {
  for (const AnalysisSpec& a : study.analyses) {
    if (a.type != AnalysisSpec::Type::kModal || !a.about_static) continue;
    const bool harmonic =
        std::any_of(study.model.loads.begin(), study.model.loads.end(), [&](const Load& load) {
          return load.time.type == TimeFunction::Type::kHarmonic &&
                 applies_in_case(load, a.load_case);
        });
    const bool listed =
        std::any_of(study.analyses.begin(), study.analyses.end(), [&](const AnalysisSpec& s) {
          return s.type == AnalysisSpec::Type::kStatic && s.load_case == a.load_case;
        });
    if (harmonic && !listed)
      diag.error(a.where.file, a.where.pointer,
                 "a modal analysis about the static equilibrium of a scene with harmonic loads "
                 "(which have no final value) needs a static analysis of its load case with "
                 "\"time\", whose equilibrium it shares; or \"about\": \"initial\"");
  }
}

}  // namespace

std::optional<Study> load_study(const Json& document, const std::string& file,
                                const std::filesystem::path& directory, Diagnostics& diag,
                                const std::vector<SegmentChoice>* pinned) {
  const size_t errors_before = diag.size(), warnings_before = diag.warnings().size();
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
      const bool control = std::any_of(name->begin(), name->end(), [](char c) {
        return static_cast<unsigned char>(c) < 0x20 || c == 0x7f;
      });
      if (name->empty() || name->find_first_of("/\\") != std::string::npos || *name == "." ||
          *name == ".." || control)
        r.error("name",
                "must be a non-empty name without path separators or control characters (it "
                "names the output folder)");
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
        } else if (scene->get<std::string>().find('\0') != std::string::npos) {
          // The system would read the path only up to the NUL: another file.
          r.error("scene", "the scene file path contains a NUL character");
        } else if (const auto status = std::filesystem::status(p, ec); ec || !exists(status)) {
          // ec also tells of a loop of links or a folder that cannot be searched.
          r.error("scene", "scene file \"" + shown + "\" " +
                               (ec && ec != std::errc::no_such_file_or_directory
                                    ? "cannot be opened: " + ec.message()
                                    : std::string("not found")));
        } else if (is_directory(status)) {
          r.error("scene", "scene file \"" + shown + "\" is a directory");
        } else if (!is_regular_file(status)) {
          // A pipe would block the check until something writes to it; a device may never end.
          r.error("scene", "scene file \"" + shown + "\" is not a regular file");
        } else if (std::filesystem::equivalent(p, file, ec)) {
          r.error("scene", "scene file \"" + shown +
                               "\" is this study file: the scene file must hold the scene object");
        } else if (const auto j = read_json_file(p.string(), shown, diag)) {
          if (j->is_string()) {
            // Scene files are not followed further, so references cannot loop.
            diag.error(shown, "",
                       "expected the scene object, got a string (a scene file cannot name "
                       "another scene file)");
          } else {
            model = load_scene(*j, {shown, ""}, diag, pinned);
            study.document["scene"] = *j;
          }
        }
      } else {
        model = load_scene(*scene, root / "scene", diag, pinned);
      }
    }

    bool every_analysis_read = false;  // (a static analysis refused is not missing)
    if (const Json* list = r.member("analyses", true)) {
      if (!list->is_array() || list->empty()) {
        r.error("analyses", "expected a non-empty array of analyses");
      } else {
        for (size_t i = 0; i < list->size(); ++i)
          if (auto a =
                  read_analysis((*list)[i], root / "analyses" / i, model ? &*model : nullptr, diag))
            study.analyses.push_back(*a);
        every_analysis_read = study.analyses.size() == list->size();
        name_analyses(study, diag);
      }
    }
    if (model) {
      study.model = std::move(*model);
      check_load_cases(study, diag);
      if (every_analysis_read) check_modal_equilibria(study, diag);
    }

    std::set<std::string> declared;  // every response name given, read or not
    if (const Json* responses = r.member("responses", false)) {
      if (!responses->is_object()) {
        r.error("responses", "expected an object of named responses");
      } else {
        // Checked even when the scene has errors (body names then go unchecked).
        const Model* m = model ? &study.model : nullptr;
        for (const auto& item : responses->items()) {
          declared.insert(item.key());
          if (auto s = read_response(item.key(), item.value(), root / "responses" / item.key(),
                                     study, m, diag))
            study.responses.push_back(*s);
        }
      }
    }
    resolve_expressions(study, diag, declared);
    if (const Json* design = r.member("study", false))
      study.design = read_design_study(*design, root / "study", study, diag);
    // What a run writes besides the tables (docs/study_files.md "Outputs").
    if (const Json* outputs = r.member("outputs", false)) {
      ObjectReader o(*outputs, root / "outputs", diag);
      if (o.is_object()) study.vtk = o.boolean("vtk", false).value_or(false);
    }
  }

  if (diag.size() > errors_before || !model) return std::nullopt;
  const std::vector<std::string> lines = diag.warning_lines();
  study.input_warnings.assign(lines.begin() + static_cast<long>(warnings_before), lines.end());
  return study;
}

namespace {

bool same_structure(const Model& a, const Model& b) {
  if (a.bodies.size() != b.bodies.size() || !same_elements(a, b) ||
      a.loads.size() != b.loads.size() || a.free_bodies != b.free_bodies ||
      a.load_cases != b.load_cases || (a.gravity.norm() > 0.0) != (b.gravity.norm() > 0.0))
    return false;
  for (size_t i = 0; i < a.bodies.size(); ++i)
    if (a.bodies[i].name != b.bodies[i].name) return false;
  for (size_t i = 0; i < a.loads.size(); ++i)
    if (a.loads[i].body != b.loads[i].body || a.loads[i].kind != b.loads[i].kind ||
        a.loads[i].load_case != b.loads[i].load_case)
      return false;
  return true;
}

}  // namespace

std::optional<Study> rebuild_scene(const Study& base, const Json& document, Diagnostics& diag,
                                   bool* full_read_needed) {
  *full_read_needed = false;
  const auto it = document.is_object() ? document.find("scene") : document.end();
  const Json* scene = it != document.end() ? &*it : nullptr;
  if (!scene || !scene->is_object()) {
    *full_read_needed = true;
    return std::nullopt;
  }
  const size_t warnings_before = diag.warning_lines().size();
  auto model =
      load_scene(*scene, Where{base.file, ""} / "scene", diag, &base.model.segment_choices);
  if (!model) return std::nullopt;
  if (!same_structure(*model, base.model)) {
    *full_read_needed = true;
    return std::nullopt;
  }
  Study s;
  s.file = base.file;
  s.directory = base.directory;
  s.name = base.name;
  s.description = base.description;
  s.analyses = base.analyses;
  s.responses = base.responses;
  s.expression_order = base.expression_order;
  s.model = std::move(*model);
  for (ResponseSpec& r : s.responses)
    if (!r.point_given && r.quantity != ResponseSpec::Quantity::kMass &&
        r.quantity != ResponseSpec::Quantity::kExpression)
      r.point = s.model.bodies[r.body].position;
  const std::vector<std::string> lines = diag.warning_lines();
  s.input_warnings.assign(lines.begin() + static_cast<long>(warnings_before), lines.end());
  return s;
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
