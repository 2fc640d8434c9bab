// Where the dense eigensolver stops being faster than Lanczos: the measurements behind
// modal_dense_is_faster and buckling_dense_is_faster. For chains and frames of growing size and
// 1..20 modes wanted, the median wall time of solve_modal (solve_buckling) with the dense solver
// and with shift-invert Lanczos, printed as tables of their ratio (Lanczos / dense: below 1,
// Lanczos is faster) and the solver kAuto picks. Below twice the pairs Lanczos computes (the
// modes, plus 12 for rigid modes in a scene not held by beams) the modal analysis solves densely
// whatever was asked, which shows as a ratio of 1. Run on an otherwise idle machine:
//   build-bench/tests/benchmarks/eigensolver_crossover [modal|buckling|both]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/analysis/buckling_analysis.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/scene/scene_loader.hpp"

namespace beamrail {
namespace {

Model load(const std::string& text) {
  Diagnostics diag;
  const auto json = parse_json(text, "crossover", diag);
  std::optional<Model> model;
  if (json) model = load_scene(*json, {"crossover", ""}, diag);
  if (!model) throw std::runtime_error(diag.format());
  return *model;
}

const char* kSteel = R"("materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},)";

std::string beam(const std::string& name, const std::string& b1, const std::string& b2,
                 const std::string& p1, const std::string& p2, const std::string& p3,
                 const std::string& section, int segments) {
  return R"({"name": ")" + name + R"(", "body1": ")" + b1 + R"(", "body2": ")" + b2 +
         R"(", "point1": )" + p1 + R"(, "point2": )" + p2 + R"(, "point3": )" + p3 +
         R"(, "material": "steel", "section": ")" + section + R"(", "segments": )" +
         std::to_string(segments) + "}";
}

// A 1 m cantilever of 10 x 12 mm steel with a 1 kg tip body; floating: its root on a free 1 kg
// body instead of the ground (six rigid modes). `load`: a 100 N compression of the tip.
std::string chain(int segments, bool floating, bool load = false) {
  return std::string("{") + kSteel +
         R"("sections": {"s": {"shape": "rectangle", "width": 0.01, "height": 0.012}},
    "bodies": [)" +
         (floating ? R"({"name": "root", "mass": 1, "inertia": [1e-4, 1e-4, 1e-4],
                        "position": [0, 0, 0]}, )"
                   : "") +
         R"({"name": "tip", "mass": 1, "inertia": [1e-4, 1e-4, 1e-4], "position": [1, 0, 0]}],
    "beams": [)" +
         beam("arm", floating ? "root" : "ground", "tip", "[0, 0, 0]", "[1, 0, 0]", "[0, 1, 0]",
              "s", segments) +
         "]" +
         (load ? R"(, "loads": [{"type": "force", "body": "tip", "value": [-100, 0, 0]}])" : "") +
         "}";
}

// The portal frame of studies/portal_frame.json (60 x 60 x 4 mm box); `load`: 10 kN down on
// each knee.
std::string portal(int segments, bool load = false) {
  return std::string("{") + kSteel +
         R"("sections": {"s": {"shape": "box", "width": 0.06, "height": 0.06, "wall": 0.004}},
    "bodies": [{"name": "a", "position": [0, 0, 3]}, {"name": "b", "position": [4, 0, 3]}],
    "beams": [)" +
         beam("left", "ground", "a", "[0, 0, 0]", "[0, 0, 3]", "[1, 0, 0]", "s", segments) + ", " +
         beam("right", "ground", "b", "[4, 0, 0]", "[4, 0, 3]", "[5, 0, 0]", "s", segments) + ", " +
         beam("girder", "a", "b", "[0, 0, 3]", "[4, 0, 3]", "[0, 0, 4]", "s", segments) + "]" +
         (load ? R"(, "loads": [{"type": "force", "body": "a", "value": [0, 0, -1e4]},
                            {"type": "force", "body": "b", "value": [0, 0, -1e4]}])"
               : "") +
         "}";
}

// studies/frame_3d.json: four tube legs, four box top beams, a 5 kg instrument on two hangers.
std::string frame_3d(int segments) {
  const auto b = [&](const char* n, const char* b1, const char* b2, const char* p1, const char* p2,
                     const char* p3,
                     const char* s) { return beam(n, b1, b2, p1, p2, p3, s, segments); };
  return std::string("{") + kSteel + R"("sections": {
      "leg": {"shape": "tube", "outer_diameter": 0.03, "wall": 0.002},
      "top": {"shape": "box", "width": 0.03, "height": 0.04, "wall": 0.002},
      "hanger": {"shape": "circle", "diameter": 0.012}},
    "bodies": [
      {"name": "a", "mass": 2.0, "inertia": [2e-3, 2e-3, 2e-3], "position": [0, 0, 1]},
      {"name": "b", "mass": 2.0, "inertia": [2e-3, 2e-3, 2e-3], "position": [1, 0, 1]},
      {"name": "c", "mass": 2.0, "inertia": [2e-3, 2e-3, 2e-3], "position": [1, 1, 1]},
      {"name": "d", "mass": 2.0, "inertia": [2e-3, 2e-3, 2e-3], "position": [0, 1, 1]},
      {"name": "i", "mass": 5.0, "inertia": [0.02, 0.03, 0.025], "position": [0.5, 0, 0.8]}],
    "beams": [)" +
         b("la", "ground", "a", "[0,0,0]", "[0,0,1]", "[1,0,0]", "leg") + ", " +
         b("lb", "ground", "b", "[1,0,0]", "[1,0,1]", "[2,0,0]", "leg") + ", " +
         b("lc", "ground", "c", "[1,1,0]", "[1,1,1]", "[2,1,0]", "leg") + ", " +
         b("ld", "ground", "d", "[0,1,0]", "[0,1,1]", "[1,1,0]", "leg") + ", " +
         b("ab", "a", "b", "[0,0,1]", "[1,0,1]", "[0,1,1]", "top") + ", " +
         b("bc", "b", "c", "[1,0,1]", "[1,1,1]", "[0,0,1]", "top") + ", " +
         b("cd", "c", "d", "[1,1,1]", "[0,1,1]", "[1,0,1]", "top") + ", " +
         b("da", "d", "a", "[0,1,1]", "[0,0,1]", "[1,1,1]", "top") + ", " +
         b("ha", "a", "i", "[0,0,1]", "[0.5,0,0.85]", "[0,1,1]", "hanger") + ", " +
         b("hb", "b", "i", "[1,0,1]", "[0.5,0,0.85]", "[1,1,1]", "hanger") + "]}";
}

// The median wall time of `run` over at least 5 calls and 0.2 s.
double median_seconds(const std::function<void()>& run) {
  std::vector<double> t;
  double total = 0.0;
  while ((t.size() < 5 || total < 0.2) && t.size() < 500) {
    const auto start = std::chrono::steady_clock::now();
    run();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    total += t.back();
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

const std::vector<int> kModes = {1, 2, 3, 4, 6, 8, 10, 12, 15, 20};

void modal_table(const char* title, const std::function<std::string(int)>& scene,
                 const std::vector<int>& sizes) {
  std::printf("\nmodal, %s: Lanczos / dense (kAuto's choice: d dense, L Lanczos)\nmodes", title);
  std::vector<Model> models;
  for (int s : sizes) {
    models.push_back(load(scene(s)));
    std::printf(" %8d", models.back().n_dofs);
  }
  std::printf("  degrees of freedom\n");
  std::vector<double> dense_1(models.size());
  for (int modes : kModes) {
    std::printf("%5d", modes);
    for (size_t i = 0; i < models.size(); ++i) {
      ModalOptions o;
      o.modes = modes;
      o.solver = EigenSolverKind::kAuto;
      Data data(models[i]);
      const ModalResult r = solve_modal(models[i], o, data);
      const char* choice = !r.ok ? "-" : r.solver == "dense" ? "d" : "L";
      const auto time = [&](EigenSolverKind kind) {
        o.solver = kind;
        return median_seconds([&] {
          Data fresh(models[i]);
          solve_modal(models[i], o, fresh);
        });
      };
      const double dense = time(EigenSolverKind::kDense);
      const double lanczos = time(EigenSolverKind::kShiftInvert);
      if (modes == 1) dense_1[i] = dense;
      std::printf("   %5.2f%s", lanczos / dense, choice);
    }
    std::printf("\n");
  }
  std::printf("dense");
  for (double t : dense_1) std::printf(" %7.3fms", 1e3 * t);
  std::printf("  (1 mode)\n");
}

void buckling_table(const char* title, const std::function<std::string(int)>& scene,
                    const std::vector<int>& sizes) {
  std::printf("\nbuckling, %s: Lanczos / dense (kAuto's choice: d dense, L Lanczos)\nmodes", title);
  std::vector<Model> references, scaled;
  for (int s : sizes) {
    const Model model = load(scene(s));
    references.push_back(with_loads(
        model, [](const Load&) { return false; }, false));
    scaled.push_back(with_loads(
        model, [](const Load&) { return true; }, false));
    std::printf(" %8d", model.n_dofs);
  }
  std::printf("  degrees of freedom\n");
  const auto run = [&](size_t i, int modes, EigenSolverKind kind) {
    Data data(references[i]);
    BucklingOptions o;
    o.modes = modes;
    o.solver = kind;
    return solve_buckling(references[i], scaled[i], o, data);
  };
  std::vector<double> dense_1(references.size());
  for (int modes : kModes) {
    std::printf("%5d", modes);
    for (size_t i = 0; i < references.size(); ++i) {
      const BucklingResult r = run(i, modes, EigenSolverKind::kAuto);
      const double dense = median_seconds([&] { run(i, modes, EigenSolverKind::kDense); });
      const double lanczos = median_seconds([&] { run(i, modes, EigenSolverKind::kShiftInvert); });
      if (modes == 1) dense_1[i] = dense;
      std::printf("   %5.2f%s", lanczos / dense, r.solver == "dense" ? "d" : "L");
    }
    std::printf("\n");
  }
  std::printf("dense");
  for (double t : dense_1) std::printf(" %7.3fms", 1e3 * t);
  std::printf("  (1 mode)\n");
}

}  // namespace
}  // namespace beamrail

int main(int argc, char** argv) {
  using namespace beamrail;
  const std::string which = argc > 1 ? argv[1] : "both";
  if (which != "buckling") {
    modal_table("cantilever chains", [](int s) { return chain(s, false); },
                {1, 2, 3, 4, 5, 6, 7, 8, 10, 12, 16, 20});
    modal_table("portal frames", [](int s) { return portal(s); }, {1, 2, 3, 4, 5, 6, 8});
    modal_table("3-D frames (studies/frame_3d.json)", frame_3d, {1, 2, 3, 4});
    modal_table("floating chains (six rigid modes)", [](int s) { return chain(s, true); },
                {2, 3, 4, 5, 6, 7, 8, 10, 12, 16, 20});
  }
  if (which != "modal") {
    buckling_table("cantilever columns", [](int s) { return chain(s, false, true); },
                   {1, 2, 3, 4, 5, 6, 8, 10, 12, 16, 20});
    buckling_table("portal frames", [](int s) { return portal(s, true); }, {1, 2, 3, 4, 6, 8});
  }
}
