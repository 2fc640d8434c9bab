#include "core/scene/diagnostics.hpp"

#include <cstdio>

namespace beamrail {
namespace {

// Control characters (from keys or values in the input) are escaped so that every problem stays
// on one line.
void append_one_line(std::string& out, const std::string& text) {
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c == '\r') {
      out += "\\r";
    } else if (u < 0x20 || u == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", u);
      out += buf;
    } else {
      out += c;
    }
  }
}

}  // namespace

void Diagnostics::error(std::string file, std::string pointer, std::string message) {
  items_.push_back({std::move(file), std::move(pointer), std::move(message)});
}

std::string Diagnostics::format() const {
  std::string out;
  for (const Diagnostic& d : items_) {
    append_one_line(out, d.file);
    out += ':';
    if (!d.pointer.empty()) {
      append_one_line(out, d.pointer);
      out += ':';
    }
    out += ' ';
    append_one_line(out, d.message);
    out += '\n';
  }
  return out;
}

std::string pointer_token(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~')
      out += "~0";
    else if (c == '/')
      out += "~1";
    else
      out += c;
  }
  return out;
}

}  // namespace beamrail
