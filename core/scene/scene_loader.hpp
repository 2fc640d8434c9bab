// Scene loading: the "scene" object of a study (docs/study_files.md) -> Model, with strict
// validation. Every problem is reported to Diagnostics with its file and JSON pointer; a Model is
// returned only when there are none.
#pragma once

#include <map>
#include <optional>
#include <string>
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

// The Model of the same scene on hyper-dual numbers (core/model/hyper_dual.hpp): forward-mode
// automatic differentiation through the whole build (sections from their dimensions, segment
// masses and inertias, centres of mass, attachment points and frames, joint stiffness). The
// numbers at the JSON pointers of `seeds` (canonical, as Where writes them) carry the derivative
// given there in their e2 part, and so every number of the model carries its derivative with
// respect to the design parameter. For a scene that load_scene built without errors, with its
// "auto" segment counts in `pinned`; reports problems as load_scene does but checks only what its
// reading checks, and reports a seed that addresses no number the build differentiates (a segment
// count, the segmentation target: nullopt, never a derivative silently 0).
std::optional<DualModel> load_dual_scene(const Json& scene, const Where& where,
                                         const std::map<std::string, double>& seeds,
                                         const std::vector<SegmentChoice>& pinned,
                                         Diagnostics& diag);

}  // namespace beamrail
