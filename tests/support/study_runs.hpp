// Studies run through the real command line in a temporary folder per test, and their CSV
// tables read independently of the program's own reader (tests/optimizer/*_test.cpp that run
// `beamrail run`). The including test target defines BEAMRAIL_EXECUTABLE.
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/support/run_process.hpp"

#ifndef BEAMRAIL_EXECUTABLE
#error "BEAMRAIL_EXECUTABLE must name the beamrail binary"
#endif

namespace beamrail::testing {

inline nlohmann::json load_json(const std::filesystem::path& path) {
  return nlohmann::json::parse(read_text(path));
}

inline void save_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}
inline void save_json(const std::filesystem::path& path, const nlohmann::json& json) {
  save_text(path, json.dump(2) + "\n");
}

// The fields of one line as written (quotes kept), split at commas outside quotes.
inline std::vector<std::string> raw_fields(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (char c : line) {
    if (c == '"') quoted = !quoted;  // a doubled quote toggles twice
    if (c == ',' && !quoted)
      out.emplace_back();
    else
      out.back() += c;
  }
  return out;
}

inline std::string unquote(const std::string& raw) {
  if (raw.size() < 2 || raw.front() != '"') return raw;
  std::string out;
  for (size_t i = 1; i + 1 < raw.size(); ++i) {
    out += raw[i];
    if (raw[i] == '"') ++i;
  }
  return out;
}

// Lines without their newlines; *whole is false when the text does not end with one.
inline std::vector<std::string> lines_of(const std::string& text, bool* whole = nullptr) {
  std::vector<std::string> lines;
  size_t start = 0;
  for (size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n') lines.push_back(text.substr(start, i - start)), start = i + 1;
  if (start < text.size()) lines.push_back(text.substr(start));
  if (whole) *whole = text.empty() || text.back() == '\n';
  return lines;
}

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  int column(const std::string& name) const {
    const auto it = std::find(header.begin(), header.end(), name);
    return it == header.end() ? -1 : static_cast<int>(it - header.begin());
  }
  const std::string& at(size_t row, const std::string& name) const {
    return rows.at(row).at(column(name));
  }
};

inline Table read_table(const std::filesystem::path& path) {
  Table t;
  const std::vector<std::string> lines = lines_of(read_text(path));
  for (size_t i = 0; i < lines.size(); ++i) {
    std::vector<std::string> fields;
    for (const std::string& f : raw_fields(lines[i])) fields.push_back(unquote(f));
    if (i == 0)
      t.header = fields;
    else
      t.rows.push_back(fields);
  }
  return t;
}

// A temporary folder per test (dir_), removed after it; `beamrail run` in it.
class StudyRuns : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "beamrail_study_runs_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }

  ProcessResult run(const std::vector<std::string>& args) {
    return run_process(BEAMRAIL_EXECUTABLE, args, dir_);
  }

  // `beamrail run study -o out --quiet [extra]`, which must exit 0.
  void run_ok(const std::filesystem::path& study, const std::string& out,
              const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args{"run", study.string(), "-o", out, "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    const ProcessResult r = run(args);
    ASSERT_TRUE(r.exited && r.status == 0)
        << "beamrail run " << study.string() << " -o " << out << ": " << r.how << "\n"
        << r.err;
  }

  std::filesystem::path write_study(const std::string& name, const nlohmann::json& study) {
    save_json(dir_ / name, study);
    return dir_ / name;
  }

  std::filesystem::path dir_;
};

// The table text with the named column's fields emptied (header kept), every other byte as is.
inline std::string without_column(const std::string& text, const std::string& name) {
  bool whole = true;
  const std::vector<std::string> lines = lines_of(text, &whole);
  if (lines.empty()) return text;
  const std::vector<std::string> header = raw_fields(lines[0]);
  const auto it = std::find(header.begin(), header.end(), name);
  if (it == header.end()) {
    ADD_FAILURE() << "no column \"" << name << "\" in " << lines[0];
    return text;
  }
  const size_t column = static_cast<size_t>(it - header.begin());
  std::string out;
  for (size_t i = 0; i < lines.size(); ++i) {
    std::vector<std::string> fields = raw_fields(lines[i]);
    if (i > 0 && column < fields.size()) fields[column].clear();
    for (size_t k = 0; k < fields.size(); ++k) out += (k ? "," : "") + fields[k];
    if (i + 1 < lines.size() || whole) out += '\n';
  }
  return out;
}

// Text equality with the first differing line in the message.
inline ::testing::AssertionResult SameText(const std::string& a, const std::string& b) {
  if (a == b) return ::testing::AssertionSuccess();
  const std::vector<std::string> la = lines_of(a), lb = lines_of(b);
  for (size_t i = 0; i < std::max(la.size(), lb.size()); ++i) {
    const std::string x = i < la.size() ? la[i] : "<none>", y = i < lb.size() ? lb[i] : "<none>";
    if (x != y)
      return ::testing::AssertionFailure()
             << "line " << i + 1 << " differs (" << la.size() << " vs " << lb.size()
             << " lines):\n  " << x << "\n  " << y;
  }
  return ::testing::AssertionFailure() << "the texts differ in their last newline";
}

// Fields first .. first + count - 1 of a CSV line without quoted fields, joined by commas.
inline std::string fields_of(const std::string& line, size_t first, size_t count) {
  std::vector<std::string> f;
  size_t start = 0;
  for (size_t i = 0; i <= line.size(); ++i)
    if (i == line.size() || line[i] == ',')
      f.push_back(line.substr(start, i - start)), start = i + 1;
  std::string out;
  for (size_t i = first; i < first + count && i < f.size(); ++i)
    out += (out.empty() ? "" : ",") + f[i];
  return out;
}

// studies/tube_cantilever_sweep.json (in `studies`) with an n_d x n_w grid (outer diameter 20..60
// mm, wall 1..5 mm) and, when segments > 0, a segmented (slower) beam.
inline nlohmann::json tube_grid(const std::filesystem::path& studies, int n_d, int n_w,
                                int segments = 0) {
  nlohmann::json s = load_json(studies / "tube_cantilever_sweep.json");
  nlohmann::json& v = s["study"]["variables"];
  v[0]["count"] = n_d;
  v[1] = nlohmann::json{{"name", "wall"},
                        {"pointer", "/scene/sections/tube/wall"},
                        {"lower", 0.001},
                        {"upper", 0.005},
                        {"count", n_w}};
  if (segments > 0) s["scene"]["beams"][0]["segments"] = segments;
  return s;
}

// Whether a summary warns that its transient is not within its tolerance (a verification rerun
// farther from the run than 10 times its tolerance).
inline bool warns_off_tolerance(const nlohmann::json& summary) {
  if (!summary.contains("warnings")) return false;
  for (const nlohmann::json& w : summary["warnings"])
    if (w.get<std::string>().find("the run is not within its tolerance") != std::string::npos ||
        w.get<std::string>().find("not within the tolerance asked") != std::string::npos)
      return true;
  return false;
}

}  // namespace beamrail::testing
