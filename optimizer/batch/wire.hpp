// Messages between the ranks of an MPI job as byte strings: numbers in the machine's own
// representation (every rank of a job runs the same binary), strings and vectors as a length and
// their contents. Reading past the end gives zeros and empty values, never undefined behaviour.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "optimizer/run/designs.hpp"

namespace beamrail {

class Packer {
 public:
  template <typename T>
  void put(T value) {
    append(&value, sizeof(T));
  }
  void put_string(const std::string& s) {
    put<int64_t>(static_cast<int64_t>(s.size()));
    append(s.data(), s.size());
  }
  void put_doubles(const std::vector<double>& v) {
    put<int64_t>(static_cast<int64_t>(v.size()));
    append(v.data(), v.size() * sizeof(double));
  }
  void put_outcome(const DesignOutcome& o) {
    put<int32_t>(static_cast<int32_t>(o.status));
    put<int32_t>(o.warnings);
    put<double>(o.wall_seconds);
    put_doubles(o.responses);
    put_string(o.message);
  }
  std::vector<char> bytes;

 private:
  void append(const void* data, size_t n) {
    if (n == 0) return;
    const size_t at = bytes.size();
    bytes.resize(at + n);
    std::memcpy(bytes.data() + at, data, n);
  }
};

class Unpacker {
 public:
  explicit Unpacker(const std::vector<char>& bytes) : bytes_(bytes) {}
  template <typename T>
  T get() {
    T value{};
    if (at_ + sizeof(T) <= bytes_.size()) std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  std::string get_string() {
    const size_t n = static_cast<size_t>(get<int64_t>());
    if (at_ > bytes_.size() || n > bytes_.size() - at_) return {};
    std::string s(bytes_.data() + at_, n);
    at_ += n;
    return s;
  }
  std::vector<double> get_doubles() {
    const size_t n = static_cast<size_t>(get<int64_t>());
    std::vector<double> v;
    if (at_ > bytes_.size() || n > (bytes_.size() - at_) / sizeof(double)) return v;
    v.resize(n);
    if (n > 0) std::memcpy(v.data(), bytes_.data() + at_, n * sizeof(double));
    at_ += n * sizeof(double);
    return v;
  }
  DesignOutcome get_outcome() {
    DesignOutcome o;
    o.status = static_cast<Status>(get<int32_t>());
    o.warnings = get<int32_t>();
    o.wall_seconds = get<double>();
    o.responses = get_doubles();
    o.message = get_string();
    return o;
  }

 private:
  const std::vector<char>& bytes_;
  size_t at_ = 0;
};

}  // namespace beamrail
