// Which design a run's VTK files draw (docs/study_files.md "VTK files"). A single run draws its
// analyses as they run. A design study draws one design after its batch, evaluated again with
// VTK output (no tables): an optimization's best design, or the row chosen with --design (a
// sweep's `index`, an optimization's `evaluation` of start 1 or `START:EVALUATION`); a
// work-precision or sensitivity study draws the study's own design (the values in the file).
#pragma once

#include <filesystem>
#include <string>

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

// Draws the chosen design of a design study whose batch has run into `output`: evaluates it again
// with VTK output into <output>/vtk. Returns the exit status: 0; 1 when the design cannot be
// evaluated or the files written; 2 when the chosen row is not in the table (an optimization
// that stopped before that evaluation).
int draw_design(const Study& study, const DesignChoice& choice, const std::filesystem::path& output,
                bool quiet);

}  // namespace beamrail
