// Derived responses: {"quantity": "expression", "expression": "max(abs(dy), abs(dz))"} computes a
// formula over the study's other responses, named as variables, with muparser (its functions:
// abs, sqrt, exp, ln, log10, sin .. atan2, min, max, sum, avg, sign, rint; operators + - * / ^,
// comparisons and ?:).
#pragma once

#include <Eigen/Core>
#include <set>
#include <string>
#include <vector>

#include "core/scene/json_reader.hpp"

namespace beamrail {

struct Study;

// Checks every expression response: its syntax, that it names only other responses, and that no
// expression reads itself through others. Sets each one's inputs and study.expression_order.
// `declared`: every response name the study file gives, read or not; an expression that names
// one whose own errors kept it out of study.responses is left out without another error.
void resolve_expressions(Study& study, Diagnostics& diag,
                         const std::set<std::string>& declared = {});

// Computes the expression responses from the others in `values` (one per study.responses, in
// place). An input that is NaN (not computed) gives NaN. Returns a warning for each expression
// that is not finite although its inputs are (a square root of a negative number, a division by
// zero).
std::vector<std::string> evaluate_expressions(const Study& study, std::vector<double>& values);

// The rows of `jacobian` (responses x variables) of the expression responses, by the chain rule
// from the rows of the responses they read: d e / d r by muparser's numerical derivative at
// `values` (the responses of the design). Where an expression has a kink along a variable's
// direction (max, min, abs or a comparison at a tie of its inputs), that difference gives the
// average of the two sides (max(dy, c) at dy = c: half the slope as the load grows, which
// differences of whole evaluations confirm, as they are central too; an adversarial review,
// 2026-12-01): there the derivative is the one as the variable grows, from one-sided differences
// of the expression along the inputs' derivatives (kExpressionKink), and `warnings` says so.
void chain_expression_derivatives(const Study& study, const std::vector<double>& values,
                                  Eigen::Ref<Eigen::MatrixXd> jacobian,
                                  std::vector<std::string>* warnings);

// The relative disagreement between the chain rule and the one-sided difference of an expression
// along a variable beyond which the expression has a kink there (smooth expressions agree to
// ~1e-9; a kink differs by a share of the slope).
inline constexpr double kExpressionKink = 1e-5;

}  // namespace beamrail
