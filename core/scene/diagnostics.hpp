// Problems found in user input, each tied to a file and a JSON pointer (RFC 6901), reported all at
// once as lines "file:/json/pointer: message".
#pragma once

#include <string>
#include <vector>

namespace beamrail {

struct Diagnostic {
  std::string file;     // as the user named it
  std::string pointer;  // RFC 6901 pointer into that file; empty for the whole document
  std::string message;
};

class Diagnostics {
 public:
  void error(std::string file, std::string pointer, std::string message);
  // Something that looks wrong but may be meant (a member 1,000 times heavier than the others):
  // reported, never refused. Warnings do not count in empty() and size().
  void warning(std::string file, std::string pointer, std::string message);
  bool empty() const { return items_.empty(); }
  size_t size() const { return items_.size(); }
  const std::vector<Diagnostic>& items() const { return items_; }
  const std::vector<Diagnostic>& warnings() const { return warnings_; }
  // One line per problem, in the order found.
  std::string format() const;
  // One line per warning, "file:/json/pointer: message", in the order found.
  std::vector<std::string> warning_lines() const;

 private:
  std::vector<Diagnostic> items_;
  std::vector<Diagnostic> warnings_;
};

// Escapes a member name for use in a JSON pointer ("~" -> "~0", "/" -> "~1").
std::string pointer_token(const std::string& key);

}  // namespace beamrail
