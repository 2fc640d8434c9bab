// The XML PolyData files (.vtp) of optimizer/output/vtk_output.hpp, written by hand: VTK's
// documented XML format with raw binary appended data (docs/study_files.md "VTK files").
#pragma once

#include <bit>
#include <cstdint>
#include <filesystem>
#include <list>
#include <string>
#include <vector>

#include "core/model/types.hpp"

namespace beamrail::vtp {

static_assert(std::endian::native == std::endian::little,
              "the VTK files are written little-endian, as the host's doubles are");

template <class T>
void put(std::string& bytes, T value) {
  bytes.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

inline void put(std::string& bytes, const Vec3& v) {
  for (int c = 0; c < 3; ++c) put(bytes, v(c));
}

inline std::string vec3_bytes(const std::vector<Vec3>& points) {
  std::string bytes;
  bytes.reserve(points.size() * 3 * sizeof(double));
  for (const Vec3& p : points) put(bytes, p);
  return bytes;
}

// One DataArray of a .vtp file, its bytes in the appended section (raw, each block preceded by
// its length as UInt64).
struct Array {
  std::string name;
  const char* type = "Float64";  // Float64, Int64, Int32, UInt8 or String
  int components = 1;
  const std::string* bytes = nullptr;  // borrowed: lives until the file is written
};

// Cells of one kind (Verts, Lines, Polys): connectivity and end offsets, Int32 (a frame holds
// far fewer than 2^31 points).
struct Cells {
  std::string connectivity, offsets;
  long count = 0;
  void add(const std::vector<int64_t>& points) {
    for (int64_t p : points) put(connectivity, static_cast<int32_t>(p));
    put(offsets, static_cast<int32_t>(connectivity.size() / sizeof(int32_t)));
    ++count;
  }
};

// One .vtp file: PolyData with field data, point data, cell data, points and cells.
class Vtp {
 public:
  void field(const std::string& name, double value) {
    owned_.emplace_back();
    put(owned_.back(), value);
    field_.push_back({name, "Float64", 1, &owned_.back()});
  }
  void point_data(const std::string& name, const std::string* bytes, int components = 3,
                  const char* type = "Float64") {
    point_.push_back({name, type, components, bytes});
  }
  void cell_data(const std::string& name, const std::string* bytes, int components = 1,
                 const char* type = "Float64") {
    cell_.push_back({name, type, components, bytes});
  }
  void points(const std::string* bytes, long n) {
    points_ = {"Points", "Float64", 3, bytes}, n_ = n;
  }
  void verts(const Cells* c) { verts_ = c; }
  void lines(const Cells* c) { lines_ = c; }
  void polys(const Cells* c) { polys_ = c; }

  // Writes the file; false with *error naming it and the system's reason.
  bool write(const std::filesystem::path& path, long long* written, std::string* error) const;

 private:
  std::vector<Array> field_, point_, cell_;
  std::list<std::string> owned_;
  Array points_;
  long n_ = 0;
  const Cells *verts_ = nullptr, *lines_ = nullptr, *polys_ = nullptr;
};

// Null-terminated strings, the bytes of a VTK String array.
inline std::string string_bytes(const std::vector<std::string>& strings) {
  std::string bytes;
  for (const std::string& s : strings) {
    bytes += s;
    bytes += '\0';
  }
  return bytes;
}

template <class T>
std::string number_bytes(const std::vector<T>& values) {
  std::string bytes;
  for (T v : values) put(bytes, v);
  return bytes;
}

}  // namespace beamrail::vtp
