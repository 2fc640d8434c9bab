#include "core/scene/diagnostics.hpp"

namespace beamrail {

void Diagnostics::error(std::string file, std::string pointer, std::string message) {
  items_.push_back({std::move(file), std::move(pointer), std::move(message)});
}

std::string Diagnostics::format() const {
  std::string out;
  for (const Diagnostic& d : items_) {
    out += d.file;
    out += ':';
    if (!d.pointer.empty()) out += d.pointer + ':';
    out += ' ';
    out += d.message;
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
