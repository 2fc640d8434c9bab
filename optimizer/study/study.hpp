// Study loading (docs/study_files.md "Study file"): the scene, the analyses to run, the named
// responses, and the optional design study, validated strictly. JSON stays here: what comes out is
// plain C++.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/analysis/buckling_analysis.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/static_analysis.hpp"
#include "core/analysis/transient.hpp"
#include "core/model/model.hpp"
#include "core/scene/json_reader.hpp"
#include "optimizer/study/design_study.hpp"

namespace beamrail {

struct AnalysisSpec {
  enum class Type { kTransient, kStatic, kModal, kBuckling };
  Type type = Type::kTransient;
  // Unique in the study; default: the type, numbered from 1 when the study has several analyses of
  // that type ("static_1", "static_2"). Responses and table names use it.
  std::string name;
  // The loads it applies: those without a case and those of this case ("": those without a case);
  // gravity always. A buckling analysis scales the case's loads and holds the others constant
  // (without a case: it scales the loads without a case and gravity).
  std::string load_case;
  TransientOptions transient;
  StaticOptions statics;
  ModalOptions modal;
  BucklingOptions buckling;
  bool about_static = false;  // modal: linearize about the static equilibrium (else: initial)
  // transient: rerun at tolerances ten times tighter and report the error. kAuto (the study
  // file's default, "auto"): where the scene moves as a mechanism and the steps are adaptive
  // (verification_reason in optimizer/run/transient_checks.cpp says why).
  enum class Verify { kAuto, kAlways, kNever };
  Verify verify = Verify::kAuto;
  // transient: a verified run found more than 10 times its tolerance off is run again at the
  // verification's tighter tolerances, whose results replace it ("refine", default true).
  bool refine = true;
  // transient: start at the static equilibrium of the loads at t = 0 (else: the scene's state)
  bool initial_static = false;
  Where where;
};

// "transient", "static", "modal", "buckling".
const char* type_name(AnalysisSpec::Type type);

// The file an analysis writes its table to: `table` ("static_displacements.csv") for an analysis
// named after its type, else "<name>.<table>".
std::string table_file(const AnalysisSpec& analysis, const std::string& table);

// Where an element's end forces are read: the element (a joint's forces are in the joint frame,
// docs/model.md "Joints"), and which end (1 or 2).
struct ElementEnd {
  ElementRef ref;
  int end = 1;
};

struct ResponseSpec {
  enum class Quantity {
    kFrequency,         // modal: Hz of elastic mode `mode`
    kBucklingFactor,    // buckling: load factor of mode `mode`
    kDisplacement,      // static: displacement of a body point along `direction` [m]
    kRotation,          // static: rotation of a body about `direction` [rad]
    kPeakDisplacement,  // transient: largest |displacement . direction| of a body point [m]
    kMass,              // structural mass [kg]
    kMaxStress,         // static: largest |N|/S + |My|/Wy + |Mz|/Wz over beams [Pa]
    kElementForce,      // static: one component of an element's end forces [N, N m]
    kJointGap,          // static: a joint's gap |p2 - p1| [m]
    kExpression,        // a formula over other responses (muparser syntax)
  };
  std::string name;
  Quantity quantity = Quantity::kMass;
  int analysis = -1;  // index of the analysis that produces it (-1: none, mass)
  int mode = 1;       // frequency, buckling_factor: 1-based mode
  // frequency: follow the mode by its shape, the mode with the largest MAC against mode `mode` of
  // the study's own design (in a design study), instead of by its number
  bool track = false;
  // frequency: the lowest elastic mode whose dominant direction (largest effective mass fraction:
  // 0..5 = x, y, z, rx, ry, rz) is this one, instead of mode `mode`; -1: by number
  int dominant = -1;
  int body = 0;                    // displacement-like quantities: body index
  Vec3 point = Vec3::Zero();       // global point in the initial configuration [m]
  bool point_given = false;        // false: the body's position (the point follows the body)
  Vec3 direction = Vec3::UnitX();  // unit vector, global (the axis of a rotation)
  // peak_displacement: the body whose frame the displacement is seen in (-1: the global frame)
  int relative_to = -1;
  ElementEnd element;      // element_force
  int component = 0;       // element_force: 0..5 = fx, fy, fz, mx, my, mz
  int joint = 0;           // joint_gap: joint index
  std::vector<int> beams;  // max_stress: beam indices considered (all when empty)
  // mass: the bodies (indices) and elements (beam and rail indices) counted; all when `subset` is
  // false
  bool subset = false;
  std::vector<int> mass_bodies, mass_beams, mass_rails;
  std::string expression;   // expression: the formula
  std::vector<int> inputs;  // expression: the responses it reads (indices)
  Where where;
};

struct Study {
  std::string file;                 // the study file as the user named it
  std::filesystem::path directory;  // where relative paths in it are resolved
  Json document;                    // the study as read, with a scene file inlined under /scene
  std::string name;
  std::string description;
  Model model;
  std::vector<AnalysisSpec> analyses;
  std::vector<ResponseSpec> responses;
  std::vector<int> expression_order;  // the expression responses, each after those it reads
  std::optional<DesignStudy> design;  // without it the analyses run once
  // "outputs": {"vtk": true}: the run writes VTK files (optimizer/output/vtk_output.hpp), as --vtk
  // does.
  bool vtk = false;
  // What in the study file looks mistyped but may be meant ("file:/pointer: message"): printed
  // by `check` and `run`, and listed among the warnings of summary.json.
  std::vector<std::string> input_warnings;
};

// Reads, validates and builds a study from a file. Reports every problem; nullopt if any.
std::optional<Study> load_study_file(const std::string& path, Diagnostics& diag);

// Validates and builds a study from a document already in memory (design variables rebuild
// studies this way). `file` names the source in messages; `directory` resolves relative paths.
// `pinned`: the segment counts the study's scene chose for "segments": "auto" (a design keeps
// them; see load_scene).
std::optional<Study> load_study(const Json& document, const std::string& file,
                                const std::filesystem::path& directory, Diagnostics& diag,
                                const std::vector<SegmentChoice>* pinned = nullptr);

// The study `base` with the document `document`, which differs from base.document in numbers of
// its scene only (a design's values): its scene is built again, the rest (analyses, responses)
// is taken from `base`, and what depends on scene numbers (a response's default point) follows.
// The result keeps no document (a design's is its evaluator's to give). nullopt when the scene is
// invalid (its problems in diag) or when the numbers change more than the Model's numbers (its
// bodies, elements or loads, or whether gravity acts): then load_study must read the whole
// document (*full_read_needed is set). The beams with "segments": "auto" keep base's counts.
std::optional<Study> rebuild_scene(const Study& base, const Json& document, Diagnostics& diag,
                                   bool* full_read_needed);

// The study document `document` with every "segments": "auto" of its scene's beams and rails
// replaced by the count in `choices` (the counts a design keeps: the study scene's), and the
// scene's "segmentation" removed once no "auto" is left: a design's document that `beamrail run`
// reproduces (a re-run of "auto" chooses for that design's own members, not the study scene's).
// The beams so written, with their counts ("column_left 14, beam 20"), or "" when none.
std::string write_segment_counts(Json& document, const std::vector<SegmentChoice>& choices);

// The index of the first analysis of the given type, or -1.
int find_analysis(const Study& study, AnalysisSpec::Type type);

// The index of the analysis named `name`, or -1.
int find_analysis(const Study& study, const std::string& name);

// The model an analysis of `load_case` sees: the loads without a case and those of the case,
// gravity (a copy only when the scene has loads of other cases).
template <class S>
ModelT<S> model_for_case(const ModelT<S>& model, const std::string& load_case) {
  return with_loads(
      model, [&](const LoadT<S>& load) { return applies_in_case(load, load_case); }, true);
}

// The analysis types and response quantities a study file may name.
extern const std::vector<std::string> kAnalysisTypes;
extern const std::vector<std::string> kResponseQuantities;

// Reads one entry of "analyses" (analysis_specs.cpp). `model` (may be null when the scene has
// errors) lets the defaults depend on the scene.
std::optional<AnalysisSpec> read_analysis(const Json& value, const Where& where, const Model* model,
                                          Diagnostics& diag);

// Reads the "study" object (design_specs.cpp); `study` supplies the responses and the document the
// pointers must address. Reports every problem.
std::optional<DesignStudy> read_design_study(const Json& value, const Where& where,
                                             const Study& study, Diagnostics& diag);

// Reads an "integrator" object into io (analysis_specs.cpp).
void read_integrator(const Json& value, const Where& where, Diagnostics& diag,
                     IntegratorOptions& io);

// Reads one named response (response_specs.cpp); model may be null when the scene has errors.
std::optional<ResponseSpec> read_response(const std::string& name, const Json& value,
                                          const Where& where, const Study& study,
                                          const Model* model, Diagnostics& diag);

}  // namespace beamrail
