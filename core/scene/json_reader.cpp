#include "core/scene/json_reader.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

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

void ObjectReader::error(const std::string& key, const std::string& message) {
  diag_.error(where_.file, at(key).pointer, message);
}

const Json* ObjectReader::member(const std::string& key, bool required) {
  known_.insert(key);
  if (!object_) return nullptr;
  const auto it = object_->find(key);
  if (it == object_->end()) {
    if (required)
      diag_.error(where_.file, where_.pointer, "missing required key \"" + key + "\"");
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

std::optional<double> ObjectReader::number(const std::string& key, bool required) {
  const Json* v = member(key, required);
  if (!v) return std::nullopt;
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
    std::ostringstream s;
    s.precision(17);
    s << "must be " << (allow_zero ? ">= 0" : "> 0") << ", got " << *x;
    error(key, s.str());
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
    const auto x = read_number((*v)[i], at(key) / i, diag_);
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

std::optional<Json> parse_json(const std::string& text, const std::string& file,
                               Diagnostics& diag) {
  try {
    return Json::parse(text);
  } catch (const Json::parse_error& e) {
    // Turn the byte offset into line and column.
    size_t line = 1, column = 1;
    for (size_t i = 0; i < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n')
        ++line, column = 1;
      else
        ++column;
    }
    std::string what = e.what();
    const size_t cut = what.find("syntax error");
    if (cut != std::string::npos) what = what.substr(cut);
    diag.error(file, "",
               "invalid JSON at line " + std::to_string(line) + ", column " +
                   std::to_string(column) + ": " + what);
  } catch (const std::exception& e) {
    diag.error(file, "", std::string("invalid JSON: ") + e.what());
  }
  return std::nullopt;
}

std::optional<Json> read_json_file(const std::string& path, const std::string& display_name,
                                   Diagnostics& diag) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    diag.error(display_name, "", "cannot read file");
    return std::nullopt;
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    diag.error(display_name, "", "cannot read file");
    return std::nullopt;
  }
  return parse_json(text.str(), display_name, diag);
}

}  // namespace beamrail
