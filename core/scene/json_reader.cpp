#include "core/scene/json_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace beamrail {
namespace {

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

}  // namespace

std::string shortest(double x, int min_digits) {
  char buf[32];
  for (int digits = min_digits; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

std::string json_type_name(const Json& value) {
  switch (value.type()) {
    case Json::value_t::null:
      return "null";
    case Json::value_t::object:
      return "an object";
    case Json::value_t::array:
      return "an array";
    case Json::value_t::string:
      return "a string";
    case Json::value_t::boolean:
      return "a boolean";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float:
      return "a number";
    default:
      return "an unsupported value";
  }
}

ObjectReader::ObjectReader(const Json& value, Where where, Diagnostics& diag)
    : where_(std::move(where)), diag_(diag) {
  if (value.is_object())
    object_ = &value;
  else
    diag_.error(where_.file, where_.pointer, "expected an object, got " + json_type_name(value));
}

ObjectReader::~ObjectReader() {
  if (!object_) return;
  for (const auto& item : object_->items()) {
    if (known_.count(item.key())) continue;
    std::string message = "unknown key \"" + item.key() + "\"";
    std::string best;
    size_t best_distance = 3;
    for (const std::string& k : known_) {
      const size_t d = edit_distance(item.key(), k);
      if (d < best_distance) best_distance = d, best = k;
    }
    if (!best.empty()) message += " (did you mean \"" + best + "\"?)";
    diag_.error(where_.file, (where_ / item.key()).pointer, message);
  }
}

void ObjectReader::allow(const std::vector<std::string>& keys) {
  known_.insert(keys.begin(), keys.end());
}

void ObjectReader::error(const std::string& key, const std::string& message) {
  diag_.error(where_.file, at(key).pointer, message);
}

const Json* ObjectReader::member(const std::string& key, bool required) {
  known_.insert(key);
  if (!object_) return nullptr;
  const auto it = object_->find(key);
  if (it == object_->end()) {
    if (required) diag_.error(where_.file, where_.pointer, "missing required key \"" + key + "\"");
    return nullptr;
  }
  return &*it;
}

std::optional<double> read_number(const Json& value, const Where& where, Diagnostics& diag) {
  if (!value.is_number()) {
    diag.error(where.file, where.pointer, "expected a number, got " + json_type_name(value));
    return std::nullopt;
  }
  const double x = value.get<double>();
  if (!std::isfinite(x)) {
    diag.error(where.file, where.pointer, "number is not finite");
    return std::nullopt;
  }
  return x;
}

namespace {

// A finite number: the common case, read without building the pointer a message would need.
bool plain_number(const Json& value) {
  return value.is_number() && std::isfinite(value.get<double>());
}

}  // namespace

std::optional<double> ObjectReader::number(const std::string& key, bool required) {
  const Json* v = member(key, required);
  if (!v) return std::nullopt;
  if (plain_number(*v)) return v->get<double>();
  return read_number(*v, at(key), diag_);
}

double ObjectReader::number_or(const std::string& key, double fallback) {
  return number(key, false).value_or(fallback);
}

std::optional<double> ObjectReader::positive(const std::string& key, bool required,
                                             bool allow_zero) {
  const auto x = number(key, required);
  if (!x) return std::nullopt;
  if (allow_zero ? *x < 0.0 : *x <= 0.0) {
    error(key, std::string("must be ") + (allow_zero ? ">= 0" : "> 0") + ", got " + shortest(*x));
    return std::nullopt;
  }
  return x;
}

std::optional<long> ObjectReader::integer(const std::string& key, bool required, long min_value) {
  const auto x = number(key, required);
  if (!x) return std::nullopt;
  if (*x != std::floor(*x) || std::abs(*x) > 1e15) {
    error(key, "expected an integer");
    return std::nullopt;
  }
  if (*x < static_cast<double>(min_value)) {
    error(key, "must be >= " + std::to_string(min_value));
    return std::nullopt;
  }
  return static_cast<long>(*x);
}

std::optional<std::string> ObjectReader::string(const std::string& key, bool required) {
  const Json* v = member(key, required);
  if (!v) return std::nullopt;
  if (!v->is_string()) {
    error(key, "expected a string, got " + json_type_name(*v));
    return std::nullopt;
  }
  return v->get<std::string>();
}

std::optional<bool> ObjectReader::boolean(const std::string& key, bool required) {
  const Json* v = member(key, required);
  if (!v) return std::nullopt;
  if (!v->is_boolean()) {
    error(key, "expected true or false, got " + json_type_name(*v));
    return std::nullopt;
  }
  return v->get<bool>();
}

std::optional<std::vector<double>> ObjectReader::numbers(const std::string& key, bool required,
                                                         int n) {
  const Json* v = member(key, required);
  if (!v) return std::nullopt;
  if (!v->is_array()) {
    error(key, "expected an array of numbers, got " + json_type_name(*v));
    return std::nullopt;
  }
  if (n >= 0 && v->size() != static_cast<size_t>(n)) {
    error(key, "expected " + std::to_string(n) + " numbers, got " + std::to_string(v->size()));
    return std::nullopt;
  }
  if (v->empty()) {
    error(key, "expected at least one number");
    return std::nullopt;
  }
  std::vector<double> out;
  bool ok = true;
  for (size_t i = 0; i < v->size(); ++i) {
    const auto x = plain_number((*v)[i]) ? std::optional<double>((*v)[i].get<double>())
                                         : read_number((*v)[i], at(key) / i, diag_);
    ok = ok && x.has_value();
    out.push_back(x.value_or(0.0));
  }
  if (!ok) return std::nullopt;
  return out;
}

std::optional<Vec3> ObjectReader::vec3(const std::string& key, bool required) {
  const auto v = numbers(key, required, 3);
  if (!v) return std::nullopt;
  return Vec3((*v)[0], (*v)[1], (*v)[2]);
}

std::optional<std::string> ObjectReader::choice(const std::string& key, bool required,
                                                const std::vector<std::string>& choices) {
  const auto s = string(key, required);
  if (!s) return std::nullopt;
  if (std::find(choices.begin(), choices.end(), *s) != choices.end()) return s;
  std::string list;
  for (const std::string& c : choices) list += (list.empty() ? "" : ", ") + ("\"" + c + "\"");
  error(key, "unknown value \"" + *s + "\" (expected one of " + list + ")");
  return std::nullopt;
}

namespace {

// "line L, column C" of the character at byte offset `index` (1-based; past the end: just after
// the last character).
std::string text_position(const std::string& text, size_t index) {
  size_t line = 1, column = 1;
  for (size_t i = 0; i < index && i < text.size(); ++i) {
    if (text[i] == '\n')
      ++line, column = 1;
    else
      ++column;
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

// The offset of the bracket that opens nesting level kMaxDepth + 1 (strings skipped).
size_t too_deep_at(const std::string& text, size_t max_depth) {
  size_t depth = 0;
  bool in_string = false, escaped = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return i;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return text.size();
}

// Builds the document from SAX events, keeping the JSON pointer of the value being read so that
// problems the plain parser hides or reports without a location get one: duplicate keys in an
// object (nlohmann keeps the last silently), numbers that overflow a double, nesting too deep to
// process safely.
class DocumentBuilder {
 public:
  static constexpr size_t kMaxDepth = 256;

  DocumentBuilder(const std::string& text, const std::string& file, Diagnostics& diag)
      : text_(text), file_(file), diag_(diag) {}

  Json& document() { return root_; }

  bool null() { return put(Json(nullptr)); }
  bool boolean(bool v) { return put(Json(v)); }
  bool number_integer(Json::number_integer_t v) { return put(Json(v)); }
  bool number_unsigned(Json::number_unsigned_t v) { return put(Json(v)); }
  bool number_float(Json::number_float_t v, const Json::string_t&) { return put(Json(v)); }
  bool string(Json::string_t& v) { return put(Json(std::move(v))); }
  bool binary(Json::binary_t& v) { return put(Json(std::move(v))); }

  bool start_object(size_t) { return open(Json::object()); }
  bool start_array(size_t) { return open(Json::array()); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }

  bool key(Json::string_t& k) {
    Frame& f = frames_.back();
    f.key = k;
    if (!f.keys.insert(k).second)
      diag_.error(file_, pending_pointer(),
                  "duplicate key \"" + k + "\" (a key may appear only once in an object)");
    return true;
  }

  bool parse_error(size_t position, const std::string& last_token, const Json::exception& e) {
    // `position` counts the characters read, the last one of the offending token included.
    const size_t index = position > 0 ? position - 1 : 0;
    if (e.id == 406) {  // a number that overflows a double, e.g. 1e999
      const size_t start = index + 1 >= last_token.size() ? index + 1 - last_token.size() : 0;
      diag_.error(file_, pending_pointer(),
                  "number " + last_token + " is out of range (not a finite double), at " +
                      text_position(text_, start));
      return false;
    }
    std::string what = e.what();
    const size_t cut = what.find("syntax error");
    if (cut != std::string::npos) what = what.substr(cut);
    diag_.error(file_, "", "invalid JSON at " + text_position(text_, index) + ": " + what);
    return false;
  }

 private:
  struct Frame {
    Json* value;
    std::string key;             // objects: the key of the member being read
    std::set<std::string> keys;  // objects: the keys seen so far
  };

  // The pointer of the value about to be read (or of the member whose key was just read).
  std::string pending_pointer() const {
    std::string p;
    for (size_t i = 0; i < frames_.size(); ++i) {
      const Frame& f = frames_[i];
      const bool last = i + 1 == frames_.size();
      p += '/';
      if (f.value->is_object())
        p += pointer_token(f.key);
      else
        p += std::to_string(f.value->size() - (last ? 0 : 1));
    }
    return p;
  }

  // Stores a value where it belongs; returns its address.
  Json* place(Json&& v) {
    if (frames_.empty()) {
      root_ = std::move(v);
      return &root_;
    }
    Json& parent = *frames_.back().value;
    if (parent.is_array()) {
      parent.push_back(std::move(v));
      return &parent.back();
    }
    Json& slot = parent[frames_.back().key];
    slot = std::move(v);
    return &slot;
  }

  bool put(Json&& v) {
    place(std::move(v));
    return true;
  }

  bool open(Json&& container) {
    if (frames_.size() >= kMaxDepth) {
      // Not by pointer: it would be hundreds of characters long.
      diag_.error(file_, "",
                  "invalid JSON at " + text_position(text_, too_deep_at(text_, kMaxDepth)) +
                      ": nesting deeper than " + std::to_string(kMaxDepth) + " levels");
      return false;
    }
    frames_.push_back({place(std::move(container)), {}, {}});
    return true;
  }

  bool close() {
    frames_.pop_back();
    return true;
  }

  const std::string& text_;
  const std::string& file_;
  Diagnostics& diag_;
  Json root_;
  std::vector<Frame> frames_;
};

}  // namespace

std::optional<Json> parse_json(const std::string& text, const std::string& file,
                               Diagnostics& diag) {
  if (text.empty()) {
    diag.error(file, "",
               "invalid JSON at line 1, column 1: the file is empty (expected a JSON object)");
    return std::nullopt;
  }
  // The parser takes a NUL byte for the end of the input and would ignore the text after it; a
  // raw NUL is never valid JSON.
  if (const size_t nul = text.find('\0'); nul != std::string::npos) {
    diag.error(file, "",
               "invalid JSON at " + text_position(text, nul) +
                   ": a NUL byte (JSON text cannot contain one)");
    return std::nullopt;
  }
  const size_t errors_before = diag.size();
  DocumentBuilder builder(text, file, diag);
  bool ok = false;
  try {
    ok = Json::sax_parse(text, &builder, Json::input_format_t::json, /*strict=*/true);
  } catch (const std::exception& e) {
    diag.error(file, "", std::string("invalid JSON: ") + e.what());
    return std::nullopt;
  }
  if (!ok) {
    if (diag.size() == errors_before) diag.error(file, "", "invalid JSON");
    return std::nullopt;
  }
  // Duplicate keys were reported; the document is still returned so that the rest of it is
  // checked too (callers fail when the diagnostics grew).
  return std::move(builder.document());
}

std::optional<Json> read_json_file(const std::string& path, const std::string& display_name,
                                   Diagnostics& diag) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    diag.error(display_name, "", "cannot read file: it is a directory");
    return std::nullopt;
  }
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    diag.error(
        display_name, "",
        std::string("cannot read file") + (err ? ": " + std::string(std::strerror(err)) : ""));
    return std::nullopt;
  }
  // Bounded: a huge file (or a device such as /dev/zero) is refused, not read into memory.
  const std::string limit = std::to_string(kMaxJsonFileBytes >> 20) + " MiB";
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxJsonFileBytes) {
    diag.error(display_name, "",
               "file too large: " + std::to_string(size) +
                   " bytes (the limit for a study or scene file is " + limit + ")");
    return std::nullopt;
  }
  std::string text;
  std::vector<char> chunk(1 << 16);
  while (in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    text.append(chunk.data(), static_cast<size_t>(in.gcount()));
    if (text.size() > kMaxJsonFileBytes) {
      diag.error(display_name, "",
                 "file too large: more than " + std::to_string(kMaxJsonFileBytes) +
                     " bytes (the limit for a study or scene file is " + limit + ")");
      return std::nullopt;
    }
  }
  if (in.bad()) {
    diag.error(display_name, "", "cannot read file: read error");
    return std::nullopt;
  }
  return parse_json(text, display_name, diag);
}

}  // namespace beamrail
