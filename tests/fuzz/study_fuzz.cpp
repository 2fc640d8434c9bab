// Fuzz target over the study loader, the path `beamrail check` takes: the input bytes are written
// as a study file and loaded with load_study_file (read, parse, validate, build the model). A
// crash, a sanitizer report, an uncaught exception or a broken contract below is a bug in the
// loader, never in this harness:
//   - a study is returned exactly when no problem was reported;
//   - every problem is one line "file:/json/pointer: message" naming the file it was found in,
//     with no control character;
//   - every number of a loaded model is finite (a huge value caught at the boundary, not as NaN
//     results or a misleading message later);
//   - the document of a loaded study (scene file inlined) loads again, as design studies do.
// In the libFuzzer build, half of the mutations are structural (json_mutator.hpp).
// Relative scene paths resolve in a scratch folder where "scenes/" holds the example scene files
// of studies/scenes, so that the seed studies that name one load as they do from studies/.
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "core/scene/diagnostics.hpp"
#include "optimizer/study/study.hpp"
#include "tests/fuzz/json_mutator.hpp"

#ifndef BEAMRAIL_FUZZ_SCENES_DIR
#error "BEAMRAIL_FUZZ_SCENES_DIR must name studies/scenes"
#endif

namespace {

namespace fs = std::filesystem;

[[noreturn]] void contract_broken(const char* what, const std::string& detail) {
  std::fprintf(stderr, "study_fuzz: %s\n%s\n", what, detail.c_str());
  std::fflush(stderr);
  abort();
}

// The scratch folder, made once per process and removed at exit; in memory when the system has a
// shared-memory folder (every input is written there). Never destroyed, so that the exit handler
// can still use it.
const fs::path& scratch() {
  static const fs::path* dir = [] {
    const fs::path base =
        access("/dev/shm", W_OK) == 0 ? fs::path("/dev/shm") : fs::temp_directory_path();
    std::string pattern = (base / "beamrail_fuzz_XXXXXX").string();
    if (!mkdtemp(pattern.data())) contract_broken("cannot create a scratch folder", pattern);
    const auto* d = new fs::path(pattern);
    std::error_code ec;
    fs::create_directory_symlink(BEAMRAIL_FUZZ_SCENES_DIR, *d / "scenes", ec);
    std::atexit([] {
      std::error_code ignored;
      fs::remove_all(scratch(), ignored);
    });
    return d;
  }();
  return *dir;
}

void check_report(const beamrail::Diagnostics& diag, const std::string& study_file) {
  const std::string text = diag.format();
  size_t lines = 0;
  for (size_t begin = 0; begin < text.size(); ++lines) {
    const size_t end = text.find('\n', begin);
    if (end == std::string::npos) contract_broken("a report line does not end", text);
    const std::string line = text.substr(begin, end - begin);
    for (const char c : line)
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
        contract_broken("a report line holds a control character", line);
    // Each line names the study file or the scene file it refers to; both are absolute paths
    // here, since the study file is.
    const bool names_a_file = line.rfind(study_file + ":", 0) == 0 || line.rfind('/', 0) == 0;
    if (!names_a_file || line.find(": ") == std::string::npos)
      contract_broken("a report line is not \"file:/json/pointer: message\"", line);
    begin = end + 1;
  }
  if (lines != diag.size()) contract_broken("a problem spans more than one line", text);
}

template <class M>
bool finite(const M& m) {
  return m.allFinite();
}
bool finite(double x) { return std::isfinite(x); }

bool finite(const beamrail::SectionProperties& s) {
  return finite(s.area) && finite(s.torsion_constant) && finite(s.iy) && finite(s.iz) &&
         finite(s.wy) && finite(s.wz);
}

bool finite(const beamrail::ElementEnds& e) {
  return finite(e.r1) && finite(e.r2) && finite(e.frame1) && finite(e.frame2) && finite(e.length);
}

// The name of the first part of the model holding a number that is not finite, or "".
std::string first_non_finite(const beamrail::Model& m) {
  if (!finite(m.gravity)) return "gravity";
  for (const beamrail::Body& b : m.bodies)
    if (!finite(b.mass) || !finite(b.inertia) || !finite(b.inertia_inverse) ||
        !finite(b.position) || !finite(b.orientation) || !finite(b.velocity) ||
        !finite(b.angular_velocity) || !finite(b.declared_mass))
      return "body " + b.name;
  for (const beamrail::Beam& e : m.beams)
    if (!finite(e.ends) || !finite(e.ea) || !finite(e.gj) || !finite(e.eiy) || !finite(e.eiz) ||
        !finite(e.damping) || !finite(e.section) || !finite(e.density))
      return "beam " + e.name;
  for (const beamrail::Rail& e : m.rails)
    if (!finite(e.ends) || !finite(e.gj) || !finite(e.eiy) || !finite(e.eiz) ||
        !finite(e.min_length) || !finite(e.damping) || !finite(e.section) || !finite(e.density))
      return "rail " + e.name;
  for (size_t k = 0; k < m.loads.size(); ++k)
    if (!finite(m.loads[k].offset) || !finite(m.loads[k].value)) return "load " + std::to_string(k);
  return "";
}

}  // namespace

#ifdef BEAMRAIL_LIBFUZZER
extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t max_size);

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t max_size,
                                          unsigned int seed) {
  beamrail::fuzz::Random rng(seed);
  if (rng.below(2) == 0) {
    std::string text(reinterpret_cast<const char*>(data), size);
    if (beamrail::fuzz::mutate_json(text, rng) && text.size() <= max_size) {
      std::copy(text.begin(), text.end(), data);
      return text.size();
    }
  }
  return LLVMFuzzerMutate(data, size, max_size);
}
#endif

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fs::path file = scratch() / "study.json";
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) contract_broken("cannot write the study file", file.string());
  }

  beamrail::Diagnostics diag;
  const auto study = beamrail::load_study_file(file.string(), diag);
  if (study.has_value() != diag.empty())
    contract_broken(study ? "a study was returned with problems reported"
                          : "the study was rejected without a reported problem",
                    diag.format());
  check_report(diag, file.string());
  if (!study) return 0;

  // What `beamrail check` prints needs a built model.
  if (study->model.bodies.empty()) contract_broken("a loaded study has no ground body", "");
  if (const std::string part = first_non_finite(study->model); !part.empty())
    contract_broken("a loaded model holds a number that is not finite", part);

  // Design studies rebuild each design from the document with the scene inlined.
  beamrail::Diagnostics again;
  const auto reloaded = beamrail::load_study(study->document, study->file, study->directory, again);
  if (!reloaded || !again.empty())
    contract_broken("the document of a loaded study does not load again", again.format());
  if (reloaded->model.n_states != study->model.n_states ||
      reloaded->analyses.size() != study->analyses.size() ||
      reloaded->responses.size() != study->responses.size())
    contract_broken("the reloaded study differs from the loaded one", study->file);
  return 0;
}
