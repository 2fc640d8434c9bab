#include "core/scene/diagnostics.hpp"

#include <cstdio>

namespace beamrail {
namespace {

// The length of the well-formed UTF-8 sequence starting at text[i], or 0.
size_t utf8_length(const std::string& text, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(i);
  size_t n = 0;
  unsigned char low = 0x80, high = 0xbf;  // the range of the second byte
  if (lead >= 0xc2 && lead <= 0xdf) {
    n = 2;
  } else if (lead >= 0xe0 && lead <= 0xef) {
    n = 3;
    if (lead == 0xe0) low = 0xa0;   // overlong
    if (lead == 0xed) high = 0x9f;  // surrogates
  } else if (lead >= 0xf0 && lead <= 0xf4) {
    n = 4;
    if (lead == 0xf0) low = 0x90;   // overlong
    if (lead == 0xf4) high = 0x8f;  // beyond U+10FFFF
  } else {
    return 0;
  }
  if (i + n > text.size() || byte(i + 1) < low || byte(i + 1) > high) return 0;
  for (size_t k = 2; k < n; ++k)
    if (byte(i + k) < 0x80 || byte(i + k) > 0xbf) return 0;
  return n;
}

// Control characters (from keys or values in the input) are escaped so that every problem stays
// on one line, and bytes that are not UTF-8 as \xNN so that the line stays readable text.
void append_one_line(std::string& out, const std::string& text) {
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x80) {
      const size_t n = utf8_length(text, i);
      if (n > 0) {
        out.append(text, i, n);
        i += n - 1;
      } else {
        char buf[8];
        std::snprintf(buf, sizeof buf, "\\x%02x", u);
        out += buf;
      }
    } else if (c == '\n') {
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

void Diagnostics::warning(std::string file, std::string pointer, std::string message) {
  warnings_.push_back({std::move(file), std::move(pointer), std::move(message)});
}

namespace {

std::string line_of(const Diagnostic& d) {
  std::string out;
  append_one_line(out, d.file);
  out += ':';
  if (!d.pointer.empty()) {
    append_one_line(out, d.pointer);
    out += ':';
  }
  out += ' ';
  append_one_line(out, d.message);
  return out;
}

}  // namespace

std::string Diagnostics::format() const {
  std::string out;
  for (const Diagnostic& d : items_) out += line_of(d) + '\n';
  return out;
}

std::vector<std::string> Diagnostics::warning_lines() const {
  std::vector<std::string> out;
  for (const Diagnostic& d : warnings_) out.push_back(line_of(d));
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
