// Scene loading: the "scene" object of a study (docs/study_files.md) -> Model, with strict
// validation. Every problem is reported to Diagnostics with its file and JSON pointer; a Model is
// returned only when there are none.
#pragma once

#include <optional>
#include <vector>

#include "core/model/model.hpp"
#include "core/scene/json_reader.hpp"

namespace beamrail {

// Builds the Model of a scene object found at `where`. Beams with "segments": "auto" get the
// counts of `pinned` (the choices of the study's scene, which the designs built from it keep so
// that their responses stay continuous in the variables) where it names them; the others are
// chosen for the scene's "segmentation" target (core/scene/auto_segments.hpp).
std::optional<Model> load_scene(const Json& scene, const Where& where, Diagnostics& diag,
                                const std::vector<SegmentChoice>* pinned = nullptr);

}  // namespace beamrail
