// A SUNDIALS direct linear solver on KLU that factors with a shared symbolic analysis: the
// ordering of a topology is computed once (SparseStructure) and every run of every design of that
// topology only factors numerically. Matrices are SUNDIALS sparse CSC matrices holding exactly the
// structure's pattern.
#pragma once

#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>

#include <memory>

#include "core/analysis/sparse_structure.hpp"

namespace beamrail {

// nullptr when SUNDIALS cannot allocate the solver. Free with SUNLinSolFree.
SUNLinearSolver make_klu_solver(std::shared_ptr<const SparseStructure> structure, SUNContext ctx);

}  // namespace beamrail
