// Scene loading: the "scene" object of a study (docs/study_files.md) -> Model, with strict
// validation. Every problem is reported to Diagnostics with its file and JSON pointer; a Model is
// returned only when there are none.
#pragma once

#include <optional>

#include "core/model/model.hpp"
#include "core/scene/json_reader.hpp"

namespace beamrail {

// Builds the Model of a scene object found at `where`.
std::optional<Model> load_scene(const Json& scene, const Where& where, Diagnostics& diag);

}  // namespace beamrail
