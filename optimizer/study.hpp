// Study loading (SPEC.md "Study file"): the scene, the analyses to run, the named responses, and
// the optional design study, validated strictly. JSON stays here: what comes out is plain C++.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/analysis/transient.hpp"
#include "core/model/model.hpp"
#include "core/scene/json_reader.hpp"

namespace beamrail {

struct AnalysisSpec {
  enum class Type { kTransient };
  Type type = Type::kTransient;
  TransientOptions transient;
  Where where;
};

struct ResponseSpec {
  enum class Quantity { kPeakDisplacement, kMass };
  std::string name;
  Quantity quantity = Quantity::kMass;
  int body = 0;                      // body index (displacement-like quantities)
  Vec3 point = Vec3::Zero();         // global point in the initial configuration [m]
  Vec3 direction = Vec3::UnitX();    // unit vector, global
  Where where;
};

struct Study {
  std::string file;         // the study file as the user named it
  std::filesystem::path directory;  // where relative paths in it are resolved
  Json document;            // the study as read, with a scene file inlined under /scene
  std::string name;
  std::string description;
  Model model;
  std::vector<AnalysisSpec> analyses;
  std::vector<ResponseSpec> responses;
};

// Reads, validates and builds a study from a file. Reports every problem; nullopt if any.
std::optional<Study> load_study_file(const std::string& path, Diagnostics& diag);

// Validates and builds a study from a document already in memory (design variables rebuild
// studies this way). `file` names the source in messages; `directory` resolves relative paths.
std::optional<Study> load_study(const Json& document, const std::string& file,
                                const std::filesystem::path& directory, Diagnostics& diag);

// The index of the analysis of the given type, or -1.
int find_analysis(const Study& study, AnalysisSpec::Type type);

}  // namespace beamrail
