#include "optimizer/output/batch_table.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "optimizer/output/tables.hpp"

namespace beamrail {
namespace {

std::string join(const CsvRow& row) {
  std::string line;
  for (size_t i = 0; i < row.size(); ++i) {
    if (i) line += ',';
    line += csv_field(row[i]);
  }
  return line + '\n';
}

// Reads the whole lines of a file; the byte length of those lines goes to *whole_bytes.
std::vector<std::string> whole_lines(const std::filesystem::path& path, size_t* whole_bytes) {
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::string> lines;
  size_t start = 0;
  *whole_bytes = 0;
  for (size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n') {
      lines.push_back(text.substr(start, i - start));
      start = i + 1;
      *whole_bytes = start;
    }
  return lines;
}

}  // namespace

CsvRow parse_csv_line(const std::string& line) {
  CsvRow out(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"')
        out.back() += '"', ++i;
      else if (c == '"')
        quoted = false;
      else
        out.back() += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

BatchTable::Opened BatchTable::open(const std::filesystem::path& path, const CsvRow& header,
                                    bool resume, std::vector<CsvRow>* existing,
                                    std::string* error) {
  path_ = path;
  header_ = header;
  existing->clear();
  std::error_code ec;
  size_t whole = 0;
  // A run killed before its header reached the file leaves no whole line: start afresh.
  const std::vector<std::string> lines = resume && std::filesystem::exists(path, ec)
                                             ? whole_lines(path, &whole)
                                             : std::vector<std::string>{};
  if (!lines.empty()) {
    if (parse_csv_line(lines.front()) != header) {
      *error = "cannot resume: " + path.string() +
               " has other columns than this study's table; remove it or run without --resume";
      return Opened::kOtherColumns;
    }
    for (size_t i = 1; i < lines.size(); ++i) {
      CsvRow row = parse_csv_line(lines[i]);
      if (row.size() == header.size()) existing->push_back(std::move(row));
    }
    // Drop an unfinished last line, then append after the whole rows.
    fd_ = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd_ >= 0 && ::ftruncate(fd_, static_cast<off_t>(whole)) == 0 &&
        ::lseek(fd_, 0, SEEK_END) >= 0) {
      written_ = static_cast<off_t>(whole);
      return Opened::kOk;
    }
  } else {
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    const std::string text = join(header);
    if (fd_ >= 0 && write_all(fd_, text)) {
      written_ = static_cast<off_t>(text.size());
      return Opened::kOk;
    }
  }
  *error = error_ = write_error(path, errno);
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  return Opened::kWriteError;
}

bool BatchTable::append(const CsvRow& row) {
  const std::string line = join(row);
  std::lock_guard<std::mutex> lock(mutex_);
  if (fd_ < 0 || !error_.empty()) return false;
  if (write_all(fd_, line)) {
    written_ += static_cast<off_t>(line.size());
    return true;
  }
  error_ = write_error(path_, errno);
  // The table stays a table of whole rows.
  if (::ftruncate(fd_, written_) != 0) error_ += " (and the part of a row written stays)";
  return false;
}

std::string BatchTable::error() {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

bool BatchTable::finalize(const std::vector<int>& key_columns, std::string* error) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (fd_ >= 0 && ::close(fd_) != 0 && error_.empty()) error_ = write_error(path_, errno);
  fd_ = -1;
  if (!error_.empty()) {
    *error = error_;
    return false;
  }
  size_t whole = 0;
  const std::vector<std::string> lines = whole_lines(path_, &whole);
  std::map<std::vector<double>, CsvRow> rows;
  for (size_t i = 1; i < lines.size(); ++i) {
    CsvRow row = parse_csv_line(lines[i]);
    if (row.size() != header_.size()) continue;
    std::vector<double> key;
    for (int c : key_columns) key.push_back(std::strtod(row[c].c_str(), nullptr));
    rows.emplace(std::move(key), std::move(row));
  }
  std::string text = join(header_);
  for (const auto& [key, row] : rows) text += join(row);
  return write_file_atomically(path_, text, error);
}

}  // namespace beamrail
