#include "optimizer/evaluation.hpp"

#include <chrono>
#include <cmath>
#include <limits>

#include "core/model/rotation.hpp"
#include "optimizer/tables.hpp"

namespace beamrail {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Bodies listed in the time series: the scene's own free bodies (not generated segment nodes).
std::vector<int> reported_bodies(const Model& model) {
  std::vector<int> out;
  for (int i : model.free_bodies)
    if (!model.bodies[i].generated) out.push_back(i);
  return out;
}

// Displacement of a body point along a direction, from the initial configuration.
struct PointTracker {
  int body;
  Vec3 offset;  // body axes
  Vec3 initial;
  Vec3 direction;
  double value(const Data& data) const {
    const Pose<double>& p = data.pose[body];
    return (p.c + p.A * offset - initial).dot(direction);
  }
};

PointTracker tracker(const Model& model, const ResponseSpec& r) {
  const Body& b = model.bodies[r.body];
  const Mat3 a0 = rotation_matrix<double>(b.orientation);
  return {r.body, a0.transpose() * (r.point - b.position), r.point, r.direction};
}

AnalysisReport run_transient_analysis(const Study& study, const Model& model,
                                      const AnalysisSpec& spec, const EvaluationOptions& options,
                                      Evaluation& evaluation) {
  AnalysisReport report;
  report.type = "transient";
  Data data(model);

  // Responses fed by this analysis.
  std::vector<std::pair<size_t, PointTracker>> peaks;
  for (size_t k = 0; k < study.responses.size(); ++k)
    if (study.responses[k].quantity == ResponseSpec::Quantity::kPeakDisplacement) {
      peaks.emplace_back(k, tracker(model, study.responses[k]));
      evaluation.responses[k] = 0.0;
    }

  CsvWriter table;
  const std::vector<int> bodies = reported_bodies(model);
  std::string table_error;
  if (!options.output_directory.empty()) {
    std::vector<std::string> header{"t"};
    for (int i : bodies)
      for (const char* c : {".x", ".y", ".z", ".q0", ".q1", ".q2", ".q3"})
        header.push_back(model.bodies[i].name + c);
    header.push_back("energy");
    table.open(options.output_directory / "timeseries.csv", header, &table_error);
  }

  bool first = true;
  double scale = 0.0;
  std::vector<double> row;
  const auto observer = [&](const TransientSample& s, const Data& d) {
    if (first) {
      report.energy_initial = s.energy();
      first = false;
    }
    report.energy_final = s.energy();
    scale = std::max({scale, std::abs(report.energy_initial), s.kinetic + std::abs(s.elastic)});
    if (scale > 0.0)
      report.energy_max_relative_change = std::max(
          report.energy_max_relative_change, std::abs(s.energy() - report.energy_initial) / scale);
    for (auto& [k, t] : peaks)
      evaluation.responses[k] = std::max(evaluation.responses[k], std::abs(t.value(d)));
    if (table.good()) {
      row.clear();
      row.push_back(s.t);
      for (int i : bodies) {
        const Pose<double>& p = d.pose[i];
        const Vec4 q = d.q[i] / d.q[i].norm();
        row.insert(row.end(), {p.c(0), p.c(1), p.c(2), q(0), q(1), q(2), q(3)});
      }
      row.push_back(s.energy());
      table.row(row);
    }
  };
  const TransientResult result = run_transient(model, spec.transient, data, observer);
  table.flush();
  report.ok = result.ok;
  report.message = result.message;
  report.stats = result.stats;
  report.t_end = result.t_reached;
  evaluation.warnings.insert(evaluation.warnings.end(), result.warnings.begin(),
                             result.warnings.end());
  if (!table_error.empty()) {
    report.ok = false;
    report.message = table_error;
  }
  if (!result.ok)
    for (auto& [k, t] : peaks) evaluation.responses[k] = kNaN;  // a partial peak is no peak
  return report;
}

}  // namespace

double structural_mass(const Model& model) {
  double m = 0.0;
  for (const Body& b : model.bodies) m += b.declared_mass;
  for (const Beam& e : model.beams) m += e.density * e.section.area * e.ends.length;
  for (const Rail& e : model.rails) m += e.density * e.section.area * e.ends.length;
  return m;
}

Evaluation evaluate(const Study& study, const Model& model, const EvaluationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Evaluation ev;
  ev.responses.assign(study.responses.size(), kNaN);
  try {
    for (size_t k = 0; k < study.responses.size(); ++k)
      if (study.responses[k].quantity == ResponseSpec::Quantity::kMass)
        ev.responses[k] = structural_mass(model);
    for (const AnalysisSpec& spec : study.analyses) {
      AnalysisReport report = run_transient_analysis(study, model, spec, options, ev);
      const bool ok = report.ok;
      const std::string message = report.message;
      ev.analyses.push_back(std::move(report));
      if (!ok) {
        ev.status = "failed";
        ev.message = "transient analysis: " + message;
        break;
      }
    }
  } catch (const std::exception& e) {
    ev.status = "failed";
    ev.message = e.what();
  }
  ev.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return ev;
}

}  // namespace beamrail
