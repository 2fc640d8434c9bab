// A SUNDIALS direct linear solver for the Newton matrices M = I - gamma J of the equations of
// motion. The position rows of M couple each body to itself only, so M is reduced to the velocity
// level: per body, P^-1 of its 7 x 7 position block; then S = B - A P^-1 U, 6 x 6 per coupled body
// pair (2.5 times fewer entries than M on a chain), factored by KLU with the topology's shared
// symbolic analysis (SparseStructure): every run of every design of a topology only factors
// numerically. Matrices are SUNDIALS sparse CSC matrices holding exactly the structure's pattern.
#pragma once

#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>

#include <memory>

#include "core/analysis/sparse_structure.hpp"

namespace beamrail {

// nullptr when SUNDIALS cannot allocate the solver. Free with SUNLinSolFree.
SUNLinearSolver make_klu_solver(std::shared_ptr<const SparseStructure> structure, SUNContext ctx);

}  // namespace beamrail
