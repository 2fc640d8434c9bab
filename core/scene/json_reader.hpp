// Strict reading of JSON input: typed getters that report every problem (missing member, wrong
// type, non-finite number, unknown member) to Diagnostics with the file and JSON pointer, instead
// of throwing. JSON stays at this edge: what is read here becomes plain C++ values.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/model/types.hpp"
#include "core/scene/diagnostics.hpp"

namespace beamrail {

using Json = nlohmann::json;

// A location in an input file.
struct Where {
  std::string file;
  std::string pointer;
  Where operator/(const std::string& key) const {
    return {file, pointer + "/" + pointer_token(key)};
  }
  Where operator/(size_t index) const { return {file, pointer + "/" + std::to_string(index)}; }
};

// The shortest text with at least min_digits significant digits that reads back as x
// ("-8.1e+10", not "-81000000000" or "-1.0000000000000001e-09").
std::string shortest(double x, int min_digits = 1);

// The JSON type of a value, as a user would name it ("number", "string", ...).
std::string json_type_name(const Json& value);

// Reads one JSON object. Every member the program understands is asked for through the getters;
// when the reader is destroyed, members never asked for are reported as unknown (with the closest
// known name as a hint).
class ObjectReader {
 public:
  ObjectReader(const Json& value, Where where, Diagnostics& diag);
  ~ObjectReader();
  ObjectReader(const ObjectReader&) = delete;
  ObjectReader& operator=(const ObjectReader&) = delete;

  bool is_object() const { return object_ != nullptr; }
  const Where& where() const { return where_; }
  Where at(const std::string& key) const { return where_ / key; }
  Diagnostics& diagnostics() { return diag_; }

  // The member, or nullptr when absent (reported when required). Marks the key as known.
  const Json* member(const std::string& key, bool required);

  std::optional<double> number(const std::string& key, bool required);
  double number_or(const std::string& key, double fallback);
  // A number > 0 (or >= 0 with allow_zero).
  std::optional<double> positive(const std::string& key, bool required, bool allow_zero = false);
  std::optional<long> integer(const std::string& key, bool required, long min_value);
  std::optional<std::string> string(const std::string& key, bool required);
  std::optional<bool> boolean(const std::string& key, bool required);
  // An array of exactly n finite numbers (n < 0: any length >= 1).
  std::optional<std::vector<double>> numbers(const std::string& key, bool required, int n);
  std::optional<Vec3> vec3(const std::string& key, bool required);
  // A string that must be one of choices.
  std::optional<std::string> choice(const std::string& key, bool required,
                                    const std::vector<std::string>& choices);

  // Accepts these keys without reading them: used when a "type" or "shape" is wrong or missing,
  // so that the members of the other variants are not reported as unknown as well.
  void allow(const std::vector<std::string>& keys);

  void error(const std::string& key, const std::string& message);

 private:
  const Json* object_ = nullptr;
  Where where_;
  Diagnostics& diag_;
  std::set<std::string> known_;
};

// Reads a finite number at a location; reports and returns nullopt otherwise.
std::optional<double> read_number(const Json& value, const Where& where, Diagnostics& diag);

// Parses a JSON document from text; reports syntax errors with line and column, numbers that
// overflow a double, and excessive nesting (then returns nullopt). Duplicate keys in an object are
// reported with their pointer but the document (last value kept) is still returned so that the
// rest can be checked: callers must treat new diagnostics as failure, not just nullopt.
std::optional<Json> parse_json(const std::string& text, const std::string& file, Diagnostics& diag);

// The largest study or scene file read [bytes]: a larger one is refused before it is parsed (the
// parsed document takes several times the text's size in memory).
inline constexpr size_t kMaxJsonFileBytes = size_t{16} << 20;

// Reads and parses a JSON file; reports unreadable, empty and too large files and syntax errors.
std::optional<Json> read_json_file(const std::string& path, const std::string& display_name,
                                   Diagnostics& diag);

}  // namespace beamrail
