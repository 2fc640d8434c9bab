// Structure-aware mutation of a study for fuzzing: parses the text as JSON and changes one value
// the way a design optimizer or a careless edit would (an extreme or degenerate number, a value of
// another type, a member or entry removed or repeated, a piece of the document copied elsewhere),
// so that inputs reach validation and model building instead of stopping at a syntax error.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace beamrail::fuzz {

// xorshift64*: the same sequence with every compiler and library.
class Random {
 public:
  explicit Random(uint64_t seed) : s_(seed ? seed : 0x9e3779b97f4a7c15ull) {}
  uint64_t next() {
    s_ ^= s_ >> 12, s_ ^= s_ << 25, s_ ^= s_ >> 27;
    return s_ * 2685821657736338717ull;
  }
  size_t below(size_t n) { return n ? static_cast<size_t>(next() % n) : 0; }

 private:
  uint64_t s_;
};

namespace detail {

using Json = nlohmann::json;

inline void collect(Json& v, std::vector<Json*>& out) {
  out.push_back(&v);
  if (v.is_object() || v.is_array())
    for (auto& child : v) collect(child, out);
}

inline Json extreme_number(Random& rng, const Json& old) {
  static const double kValues[] = {0.0,
                                   -0.0,
                                   -1.0,
                                   1.0,
                                   0.5,
                                   2.0,
                                   3.0,
                                   1e-300,
                                   5e-324,
                                   1e-12,
                                   1e-6,
                                   1e6,
                                   1e12,
                                   1e15,
                                   1e100,
                                   1e308,
                                   -1e308,
                                   1.7e308,
                                   9.007199254740993e15,
                                   100000,
                                   100001,
                                   1e7,
                                   -1e-300};
  const size_t n = sizeof kValues / sizeof *kValues;
  const size_t pick = rng.below(n + 3);
  if (pick < n) return kValues[pick];
  if (pick == n && old.is_number()) return old.get<double>() * (rng.below(2) ? 1e10 : 1e-10);
  if (pick == n + 1 && old.is_number()) return -old.get<double>();
  return static_cast<int64_t>(rng.below(20)) - 2;
}

inline Json other_value(Random& rng, const std::vector<Json*>& all) {
  switch (rng.below(9)) {
    case 0:
      return nullptr;
    case 1:
      return rng.below(2) == 1;
    case 2:
      return "";
    case 3:
      return "ground";
    case 4:
      return Json::array();
    case 5:
      return Json::object();
    case 6:
      return Json::array({0, 0, 0});
    default:
      return *all[rng.below(all.size())];  // a copy of some part of the document
  }
}

}  // namespace detail

// Applies one structural change to `text`; false when it is not a JSON document.
inline bool mutate_json(std::string& text, Random& rng) {
  using detail::Json;
  Json doc = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return false;
  std::vector<Json*> all;
  detail::collect(doc, all);
  Json& v = *all[rng.below(all.size())];
  switch (rng.below(6)) {
    case 0:
    case 1:  // a number at an extreme, or any value replaced by one
      v = detail::extreme_number(rng, v);
      break;
    case 2:  // a value of another type, or a copy of another part
      v = detail::other_value(rng, all);
      break;
    case 3:  // one member or entry less
      if (v.is_object() && !v.empty()) {
        auto it = v.begin();
        std::advance(it, static_cast<long>(rng.below(v.size())));
        v.erase(it);
      } else if (v.is_array() && !v.empty()) {
        v.erase(v.begin() + static_cast<long>(rng.below(v.size())));
      }
      break;
    case 4:  // an entry repeated (same name twice), or a member renamed to a known key
      if (v.is_array() && !v.empty()) {
        v.push_back(v[rng.below(v.size())]);
      } else if (v.is_object() && !v.empty()) {
        auto it = v.begin();
        std::advance(it, static_cast<long>(rng.below(v.size())));
        const Json* other = all[rng.below(all.size())];
        std::string key = it.key() + "_";
        if (other->is_object() && !other->empty()) key = other->begin().key();
        Json moved = it.value();
        v.erase(it);
        v[key] = std::move(moved);
      }
      break;
    default:  // a number nudged by one ulp-ish step, or a string emptied
      if (v.is_number())
        v = v.get<double>() * (1.0 + 1e-15 * (static_cast<double>(rng.below(5)) - 2.0));
      else if (v.is_string())
        v = std::string();
      break;
  }
  text = doc.dump(rng.below(2) ? -1 : 1, ' ', false, Json::error_handler_t::replace);
  return true;
}

}  // namespace beamrail::fuzz
