// Which design a run's VTK files draw (docs/study_files.md "VTK files"). A single run draws its
// analyses as they run. A design study draws one design after its batch, evaluated again with
// VTK output (no tables): an optimization's best design, or the row chosen with --design (a
// sweep's `index`, an optimization's `evaluation` of start 1 or `START:EVALUATION`); a
// work-precision or sensitivity study draws the study's own design (the values in the file).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "optimizer/output/run_outcome.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {

struct DesignChoice {
  enum class Kind { kNone, kOwn, kBest, kSweepRow, kHistoryRow };
  Kind kind = Kind::kNone;
  long index = 0;  // sweep: the row's index
  long start = 1;  // optimize: the row's start and evaluation
  long evaluation = 0;
};

// The design to draw, from whether VTK files are wanted (--vtk or "outputs") and --design (null
// when not given). "" when the choice is valid, else what is wrong (bad input, exit status 2):
// --design without VTK files, on a study without designs, out of the study's range, or a sweep
// with VTK files but no --design.
std::string choose_design(const Study& study, bool vtk, const std::string* design,
                          DesignChoice* choice);

// The design a design study's VTK files draw (`choice`, not kNone), read from the batch's files
// in `output`: outcome kOk with the design's study (rebuilt from its values) and what the VTK
// files record of it, or why it cannot be drawn (`outcome.message`): kFailed (best.json cannot be
// read, the design is invalid), kBadInput (the chosen row is not in history.csv: an optimization
// that stopped before that evaluation). Reads only: cli/batch_commands.hpp evaluates the design
// with VTK output.
struct DesignToDraw {
  RunOutcome outcome;
  std::optional<Study> study;
  nlohmann::json record;  // the "design" entry of the VTK files: which design, its values
  // What the messages call it: "the best design", "design 3", "design 2:14", ...
  std::string description;
};
DesignToDraw design_to_draw(const Study& study, const DesignChoice& choice,
                            const std::filesystem::path& output);

}  // namespace beamrail
