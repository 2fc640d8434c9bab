#include "optimizer/output/vtp_file.hpp"

#include <cerrno>
#include <cstdio>

#include "optimizer/output/tables.hpp"

namespace beamrail::vtp {

bool Vtp::write(const std::filesystem::path& path, long long* written, std::string* error) const {
  std::string xml =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" "
      "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<PolyData>\n";
  std::vector<const std::string*> blocks;
  uint64_t offset = 0;
  const auto array = [&](const Array& a, bool named) {
    // VTK reads string arrays (null-terminated strings) from <Array>, numbers from <DataArray>.
    xml += std::string(a.type) == "String" ? "<Array type=\"" : "<DataArray type=\"";
    xml += a.type;
    xml += "\"";
    if (named) xml += " Name=\"" + a.name + "\"";
    if (a.components != 1) xml += " NumberOfComponents=\"" + std::to_string(a.components) + "\"";
    xml += " format=\"appended\" offset=\"" + std::to_string(offset) + "\"/>\n";
    blocks.push_back(a.bytes);
    offset += sizeof(uint64_t) + a.bytes->size();
  };
  const auto section = [&](const char* tag, const std::vector<Array>& arrays) {
    if (arrays.empty()) return;
    xml += "<";
    xml += tag;
    xml += ">\n";
    for (const Array& a : arrays) array(a, true);
    xml += "</";
    xml += tag;
    xml += ">\n";
  };
  if (!field_.empty()) {
    xml += "<FieldData>\n";
    for (const Array& a : field_) {
      xml += "<DataArray type=\"Float64\" Name=\"" + a.name +
             "\" NumberOfTuples=\"1\" format=\"appended\" offset=\"" + std::to_string(offset) +
             "\"/>\n";
      blocks.push_back(a.bytes);
      offset += sizeof(uint64_t) + a.bytes->size();
    }
    xml += "</FieldData>\n";
  }
  const auto count = [](const Cells* c) { return std::to_string(c ? c->count : 0); };
  xml += "<Piece NumberOfPoints=\"" + std::to_string(n_) + "\" NumberOfVerts=\"" + count(verts_) +
         "\" NumberOfLines=\"" + count(lines_) + "\" NumberOfStrips=\"0\" NumberOfPolys=\"" +
         count(polys_) + "\">\n";
  section("PointData", point_);
  section("CellData", cell_);
  xml += "<Points>\n";
  array(points_, false);
  xml += "</Points>\n";
  const auto cells = [&](const char* tag, const Cells* c) {
    if (!c || c->count == 0) return;
    xml += "<";
    xml += tag;
    xml += ">\n";
    array({"connectivity", "Int32", 1, &c->connectivity}, true);
    array({"offsets", "Int32", 1, &c->offsets}, true);
    xml += "</";
    xml += tag;
    xml += ">\n";
  };
  cells("Verts", verts_);
  cells("Lines", lines_);
  cells("Polys", polys_);
  xml += "</Piece>\n</PolyData>\n<AppendedData encoding=\"raw\">\n_";

  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) {
    *error = write_error(path, errno);
    return false;
  }
  bool ok = std::fwrite(xml.data(), 1, xml.size(), f) == xml.size();
  long long total = static_cast<long long>(xml.size());
  for (const std::string* b : blocks) {
    if (!ok) break;
    const uint64_t n = b->size();
    ok = std::fwrite(&n, sizeof n, 1, f) == 1 && std::fwrite(b->data(), 1, n, f) == n;
    total += static_cast<long long>(sizeof n + n);
  }
  static const std::string tail = "\n</AppendedData>\n</VTKFile>\n";
  ok = ok && std::fwrite(tail.data(), 1, tail.size(), f) == tail.size();
  total += static_cast<long long>(tail.size());
  const int e = errno;
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed) {
    *error = write_error(path, ok ? errno : e);
    return false;
  }
  *written += total;
  return true;
}

}  // namespace beamrail::vtp
