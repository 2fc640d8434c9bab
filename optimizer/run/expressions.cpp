#include "optimizer/run/expressions.hpp"

#include <muParser.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <mutex>

#include "optimizer/run/number_text.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {
namespace {

// Parsers are made and used one at a time: muparser keeps state shared between parsers (its
// locale). An expression costs microseconds; designs evaluate in parallel around it.
std::mutex& parser_mutex() {
  static std::mutex m;
  return m;
}

// An assignment operator in the expression, "" when none: "=", or "+=" and the like, not a
// comparison (==, <=, >=, !=).
std::string assignment(const std::string& expression) {
  for (size_t i = 0; i < expression.size(); ++i) {
    if (expression[i] != '=') continue;
    const char before = i > 0 ? expression[i - 1] : ' ';
    if (i + 1 < expression.size() && expression[i + 1] == '=') {  // "==": skip its second sign
      ++i;
      continue;
    }
    if (before == '<' || before == '>' || before == '!') continue;
    return std::string("+-*/^").find(before) != std::string::npos ? std::string(1, before) + "="
                                                                  : "=";
  }
  return "";
}

// Every name the expression uses as a variable (muparser creates them through the factory), and
// what makes it more than a formula of them into *problem ("" when nothing): an assignment
// ("buckling = buckling * 100" wrote 385.02 into the response buckling, reported as such with
// status ok; an adversarial review, 2026-12-01), or several results ("stress, buckling" gave the
// last).
std::vector<std::string> used_names(const std::string& expression, std::string* problem) {
  problem->clear();
  if (const std::string op = assignment(expression); !op.empty()) {
    *problem = "an assignment (\"" + op +
               "\") would write into a response; an expression is a formula of responses "
               "(compare with ==)";
    return {};
  }
  std::lock_guard<std::mutex> lock(parser_mutex());
  std::deque<double> storage;
  mu::Parser parser;
  parser.SetVarFactory(
      [](const char*, void* data) -> double* {
        auto* s = static_cast<std::deque<double>*>(data);
        s->push_back(1.0);
        return &s->back();
      },
      &storage);
  parser.SetExpr(expression);
  std::vector<std::string> names;
  for (const auto& [name, value] : parser.GetUsedVar()) names.push_back(name);
  parser.Eval();
  if (parser.GetNumResults() > 1)
    *problem = std::to_string(parser.GetNumResults()) +
               " results separated by commas; an expression gives one number";
  return names;
}

int response_index(const Study& study, const std::string& name) {
  for (size_t k = 0; k < study.responses.size(); ++k)
    if (study.responses[k].name == name) return static_cast<int>(k);
  return -1;
}

}  // namespace

void resolve_expressions(Study& study, Diagnostics& diag, const std::set<std::string>& declared) {
  std::vector<int> expressions;
  for (size_t k = 0; k < study.responses.size(); ++k) {
    ResponseSpec& r = study.responses[k];
    if (r.quantity != ResponseSpec::Quantity::kExpression) continue;
    const Where at = r.where / "expression";
    std::vector<std::string> names;
    try {
      std::string problem;
      names = used_names(r.expression, &problem);
      if (!problem.empty()) {
        diag.error(at.file, at.pointer, problem + " in \"" + r.expression + "\"");
        continue;
      }
    } catch (const mu::Parser::exception_type& e) {
      diag.error(at.file, at.pointer, e.GetMsg() + " in \"" + r.expression + "\"");
      continue;
    }
    bool ok = true;
    r.inputs.clear();
    for (const std::string& name : names) {
      const int i = response_index(study, name);
      if (i == static_cast<int>(k)) {
        diag.error(at.file, at.pointer, "the expression reads its own response \"" + name + "\"");
        ok = false;
      } else if (i < 0 && declared.count(name)) {
        ok = false;  // that response's own errors are reported
      } else if (i < 0) {
        std::string known;
        for (const ResponseSpec& s : study.responses)
          if (s.name != r.name) known += (known.empty() ? "\"" : ", \"") + s.name + "\"";
        diag.error(at.file, at.pointer,
                   "\"" + name + "\" is no response of the study (its other responses: " +
                       (known.empty() ? std::string("none") : known) + ")");
        ok = false;
      } else {
        r.inputs.push_back(i);
      }
    }
    if (ok) expressions.push_back(static_cast<int>(k));
  }
  // Each expression after those it reads; a cycle is reported at each expression on it.
  std::map<int, int> state;  // 0 unvisited, 1 on the path, 2 done
  study.expression_order.clear();
  std::function<bool(int)> visit = [&](int k) {
    if (state[k] == 2) return true;
    if (state[k] == 1) return false;
    state[k] = 1;
    bool ok = true;
    for (int i : study.responses[k].inputs)
      if (study.responses[i].quantity == ResponseSpec::Quantity::kExpression) ok = visit(i) && ok;
    state[k] = 2;
    if (!ok) {
      const Where at = study.responses[k].where / "expression";
      diag.error(at.file, at.pointer,
                 "the expression reads itself through other expressions (a cycle)");
      return false;
    }
    study.expression_order.push_back(k);
    return true;
  };
  for (int k : expressions) visit(k);
}

std::vector<std::string> evaluate_expressions(const Study& study, std::vector<double>& values) {
  std::vector<std::string> warnings;
  for (int k : study.expression_order) {
    const ResponseSpec& r = study.responses[k];
    bool inputs_finite = true, inputs_known = true;
    for (int i : r.inputs) {
      inputs_finite = inputs_finite && std::isfinite(values[i]);
      inputs_known = inputs_known && !std::isnan(values[i]);
    }
    if (!inputs_known) {
      values[k] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    try {
      std::lock_guard<std::mutex> lock(parser_mutex());
      mu::Parser parser;
      std::vector<double> inputs = values;  // the parser reads a copy: nothing writes a response
      for (int i : r.inputs) parser.DefineVar(study.responses[i].name, &inputs[i]);
      parser.SetExpr(r.expression);
      values[k] = parser.Eval();
    } catch (const mu::Parser::exception_type& e) {
      values[k] = std::numeric_limits<double>::quiet_NaN();
      warnings.push_back("expression \"" + r.name + "\": " + e.GetMsg());
      continue;
    }
    if (inputs_finite && !std::isfinite(values[k])) {
      std::string inputs;
      for (int i : r.inputs)
        inputs += (inputs.empty() ? "" : ", ") + study.responses[i].name + " = " +
                  format_number(values[i]);
      warnings.push_back("expression \"" + r.name + "\" is " + format_number(values[k]) +
                         " where its inputs are finite (" + inputs + ")");
    }
  }
  return warnings;
}

void chain_expression_derivatives(const Study& study, const std::vector<double>& values,
                                  Eigen::Ref<Eigen::MatrixXd> jacobian,
                                  std::vector<std::string>* warnings) {
  for (int k : study.expression_order) {
    const ResponseSpec& r = study.responses[k];
    jacobian.row(k).setZero();
    std::vector<double> at = values;  // the parser varies one input at a time
    std::lock_guard<std::mutex> lock(parser_mutex());
    mu::Parser parser;
    for (int i : r.inputs) parser.DefineVar(study.responses[i].name, &at[i]);
    parser.SetExpr(r.expression);
    for (int i : r.inputs) {
      // muparser's five-point difference, step 1e-7 |x| (1e-10 at 0): ~1e-9 relative.
      const double partial = parser.Diff(&at[i], values[i]);
      at[i] = values[i];
      jacobian.row(k) += partial * jacobian.row(i);
    }
    // Along each variable's direction (the inputs' derivatives), one-sided differences of the
    // expression at steps h and h / 2 (Richardson: second order), h moving no input by more than
    // the parser's own step.
    std::string kinked;
    for (Eigen::Index j = 0; j < jacobian.cols(); ++j) {
      double h = std::numeric_limits<double>::infinity();
      bool known = std::isfinite(values[k]);
      for (int i : r.inputs) {
        const double d = jacobian(i, j);
        known = known && std::isfinite(d) && std::isfinite(values[i]);
        if (d != 0.0)
          h = std::min(h, (values[i] != 0.0 ? 1e-7 * std::abs(values[i]) : 1e-10) / std::abs(d));
      }
      if (!known || !std::isfinite(h)) continue;  // NaN stays NaN; no input moves: 0
      const auto along = [&](double step) {
        for (int i : r.inputs) at[i] = values[i] + step * jacobian(i, j);
        const double e = parser.Eval();
        for (int i : r.inputs) at[i] = values[i];
        return (e - values[k]) / step;
      };
      const double one_sided = 2.0 * along(0.5 * h) - along(h);
      const double chain = jacobian(k, j);
      // Rounding of the differences: eps |e| / h, with room.
      const double noise = 1e3 * std::numeric_limits<double>::epsilon() * std::abs(values[k]) / h;
      if (std::abs(one_sided - chain) >
          kExpressionKink * std::max(std::abs(one_sided), std::abs(chain)) + noise) {
        jacobian(k, j) = one_sided;
        kinked += (kinked.empty() ? "\"" : ", \"") +
                  (study.design && j < static_cast<Eigen::Index>(study.design->variables.size())
                       ? study.design->variables[j].name
                       : std::to_string(j + 1)) +
                  "\"";
      }
    }
    if (!kinked.empty() && warnings)
      warnings->push_back("expression \"" + r.name +
                          "\" has a kink at this design (max, min, abs or a comparison at a tie "
                          "of its inputs) along variable(s) " +
                          kinked + ": its derivative there is the one as the variable grows");
  }
}

}  // namespace beamrail
