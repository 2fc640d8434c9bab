// Result files: CSV tables written in whole rows, and files replaced atomically.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace beamrail {

// Shortest text that reads back as exactly x ("nan", "inf", "-inf" for non-finite values).
std::string format_number(double x);

// A CSV table appended one whole row at a time. Rows are buffered and handed to the operating
// system in single write calls that end at a row boundary, so a killed process leaves whole rows.
class CsvWriter {
 public:
  CsvWriter() = default;
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  // Creates (truncates) the file and writes the header. Returns false with a message on error.
  bool open(const std::filesystem::path& path, const std::vector<std::string>& header,
            std::string* error);
  // Opens an existing table for appending (its header is kept).
  bool append(const std::filesystem::path& path, std::string* error);

  // Adds one row; fields are already formatted.
  void row(const std::vector<std::string>& fields);
  // Adds one row of numbers.
  void row(const std::vector<double>& values);
  // Hands buffered rows to the operating system; `sync` also forces them to disk.
  bool flush(bool sync = false);
  bool good() const { return fd_ >= 0 && ok_; }

 private:
  int fd_ = -1;
  bool ok_ = true;
  std::string buffer_;
};

// Writes text to path through a temporary file and a rename, so readers see the old or the new
// file, never a partial one.
bool write_file_atomically(const std::filesystem::path& path, const std::string& text,
                           std::string* error);

// Quotes a CSV field when it holds a comma, quote or newline.
std::string csv_field(const std::string& text);

}  // namespace beamrail
