#include "optimizer/run/result_tables.hpp"

#include "core/model/element_kinds.hpp"
#include "core/model/joint_forces.hpp"
#include "optimizer/run/number_text.hpp"

namespace beamrail {

std::vector<ResultTable> static_tables(const std::string& prefix, const Model& model,
                                       const Data& data) {
  ResultTable displacements{
      prefix + "static_displacements.csv", {"body", "dx", "dy", "dz", "rx", "ry", "rz"}, {}};
  for (int i : model.free_bodies) {
    const Body& b = model.bodies[i];
    const Vec3 d = data.pose[i].u;
    const Vec3& r = data.rotation[i];
    displacements.rows.push_back({b.name, format_number(d(0)), format_number(d(1)),
                                  format_number(d(2)), format_number(r(0)), format_number(r(1)),
                                  format_number(r(2))});
  }
  ResultTable forces{
      prefix + "element_forces.csv", {"element", "end", "fx", "fy", "fz", "mx", "my", "mz"}, {}};
  const auto rows = [&](const std::string& name, const EndForces& f) {
    for (int end = 1; end <= 2; ++end) {
      const Vec6& v = end == 1 ? f.end1 : f.end2;
      std::vector<std::string> row{name, std::to_string(end)};
      for (int c = 0; c < 6; ++c) row.push_back(format_number(v(c)));
      forces.rows.push_back(std::move(row));
    }
  };
  for_each_element(model, [&](auto kind, const auto& e, int index) {
    rows(e.name, decltype(kind)::end_forces(model, data.pose, index));
  });
  std::vector<ResultTable> out{std::move(displacements), std::move(forces)};
  if (model.joints.empty()) return out;
  ResultTable gaps{prefix + "joint_gaps.csv", {"joint", "gap", "gx", "gy", "gz", "angle"}, {}};
  for (const Joint& j : model.joints) {
    const Pose<double>&b1 = data.pose[j.body1], &b2 = data.pose[j.body2];
    const Vec3 g = joint_gap(j, b1, b2);
    gaps.rows.push_back({j.name, format_number(g.norm()), format_number(g(0)), format_number(g(1)),
                         format_number(g(2)), format_number(joint_angle(j, b1, b2))});
  }
  out.push_back(std::move(gaps));
  return out;
}

ResultTable static_path_table(const std::string& prefix, const Model& model,
                              const StaticResult& result) {
  ResultTable path{prefix + "static_path.csv",
                   {"point", "load_factor", "arc_length", "iterations", "body", "dx", "dy", "dz",
                    "rx", "ry", "rz"},
                   {}};
  for (size_t k = 0; k < result.path.size(); ++k) {
    const StaticPathPoint& p = result.path[k];
    for (size_t b = 0; b < result.path_bodies.size() && b < p.displacement.size(); ++b) {
      std::vector<std::string> row{std::to_string(k), format_number(p.load_factor),
                                   format_number(p.arc_length), std::to_string(p.iterations),
                                   model.bodies[result.path_bodies[b]].name};
      for (int c = 0; c < 3; ++c) row.push_back(format_number(p.displacement[b](c)));
      for (int c = 0; c < 3; ++c) row.push_back(format_number(p.rotation[b](c)));
      path.rows.push_back(std::move(row));
    }
  }
  return path;
}

std::vector<ResultTable> modal_tables(const std::string& prefix, const Model& model,
                                      const ModalResult& result) {
  std::vector<std::string> header{"mode", "frequency_hz", "kind", "dominant"};
  for (const char* column : {"participation_", "effective_mass_", "effective_mass_fraction_"})
    for (const char* d : kDirectionNames) header.push_back(std::string(column) + d);
  ResultTable modes{prefix + "modes.csv", header, {}};
  ResultTable shapes{
      prefix + "mode_shapes.csv", {"mode", "body", "dx", "dy", "dz", "rx", "ry", "rz"}, {}};
  int elastic = 0;
  for (const Mode& mode : result.modes) {
    const char* kind = mode.kind == Mode::Kind::kRigid      ? "rigid"
                       : mode.kind == Mode::Kind::kUnstable ? "unstable"
                                                            : "elastic";
    const int number = mode.kind == Mode::Kind::kRigid ? 0 : ++elastic;
    const int dominant = dominant_direction(mode, result);
    std::vector<std::string> row{std::to_string(number), format_number(mode.frequency_hz), kind,
                                 dominant >= 0 ? kDirectionNames[dominant] : "none"};
    const Vec6 fraction = effective_mass_fraction(mode, result);
    for (int d = 0; d < 6; ++d) row.push_back(format_number(mode.participation(d)));
    for (int d = 0; d < 6; ++d)
      row.push_back(format_number(mode.participation(d) * mode.participation(d)));
    for (int d = 0; d < 6; ++d) row.push_back(format_number(fraction(d)));
    modes.rows.push_back(std::move(row));
    if (mode.kind == Mode::Kind::kRigid) continue;
    for (int k = 0; k < model.n_free(); ++k) {
      std::vector<std::string> shape_row{std::to_string(number),
                                         model.bodies[model.free_bodies[k]].name};
      for (int c = 0; c < 6; ++c) shape_row.push_back(format_number(mode.shape(6 * k + c)));
      shapes.rows.push_back(std::move(shape_row));
    }
  }
  return {std::move(modes), std::move(shapes)};
}

std::vector<ResultTable> buckling_tables(const std::string& prefix, const Model& model,
                                         const BucklingResult& result) {
  ResultTable factors{prefix + "buckling.csv", {"mode", "factor", "nonlinearity"}, {}};
  ResultTable shapes{
      prefix + "buckling_shapes.csv", {"mode", "body", "dx", "dy", "dz", "rx", "ry", "rz"}, {}};
  for (size_t m = 0; m < result.modes.size(); ++m) {
    const BucklingMode& mode = result.modes[m];
    const std::string number = std::to_string(m + 1);
    factors.rows.push_back({number, format_number(mode.factor), format_number(mode.nonlinearity)});
    for (int k = 0; k < model.n_free(); ++k) {
      std::vector<std::string> row{number, model.bodies[model.free_bodies[k]].name};
      for (int c = 0; c < 6; ++c) row.push_back(format_number(mode.shape(6 * k + c)));
      shapes.rows.push_back(std::move(row));
    }
  }
  return {std::move(factors), std::move(shapes)};
}

}  // namespace beamrail
