// Result files: CSV tables written in whole rows, and files replaced atomically.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

#include "optimizer/run/number_text.hpp"

namespace beamrail {

// Writes all of text to the file descriptor, retrying short and interrupted writes; false on an
// error (errno says which).
bool write_all(int fd, const std::string& text);

// Writes the whole rows `text` (each ending in '\n') to fd, whose file offset is `offset`, in
// pieces that end at a row's end and stay within one 4 KiB page of the file where a row fits: a
// process killed outright can stop a write between pages, never within one. False on an error.
bool write_rows(int fd, const std::string& text, off_t offset);

// A CSV table appended one whole row at a time. Rows are buffered and handed to the operating
// system in write calls that end at a row boundary (write_rows), so a killed process leaves whole
// rows;
// after a write error (disk full, file-size limit) the rows written in part are cut off again, the
// table takes no more rows, and error() names the file and the system's reason.
//
// A staged table is written under `<path>.partial` and renamed to `path` by commit(): the table at
// `path` is replaced at once, and until then the previous one stays. Errors name `path`.
class CsvWriter {
 public:
  CsvWriter() = default;
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  // Creates (truncates) the file and writes the header. Returns false with a message on error.
  bool open(const std::filesystem::path& path, const std::vector<std::string>& header,
            std::string* error, bool staged = false);
  // Opens an existing table for appending (its header is kept).
  bool append(const std::filesystem::path& path, std::string* error);

  // Adds one row; fields are already formatted.
  void row(const std::vector<std::string>& fields);
  // Adds one row of numbers.
  void row(const std::vector<double>& values);
  // Hands buffered rows to the operating system; `sync` also forces them to disk.
  bool flush(bool sync = false);
  // Flushes, closes and (staged) renames the table into place, also after a write error (the rows
  // written are whole). False with *error on any error so far.
  bool commit(std::string* error);
  bool good() const { return fd_ >= 0 && ok_; }
  // The first error ("cannot write <path>: <reason>"), empty when none.
  const std::string& error() const { return error_; }
  // Where the rows go now (`<path>.partial` while a staged table is open).
  const std::filesystem::path& file() const { return file_; }

 private:
  void fail(const char* what);
  int fd_ = -1;
  bool ok_ = true;
  std::string buffer_;
  std::filesystem::path path_, file_;
  off_t written_ = 0;  // bytes of whole rows in the file
  std::string error_;
};

// Writes text to path through a temporary file and a rename, so readers see the old or the new
// file, never a partial one.
bool write_file_atomically(const std::filesystem::path& path, const std::string& text,
                           std::string* error);

// "cannot write <path>: <strerror(errno_value)>".
std::string write_error(const std::filesystem::path& path, int errno_value);

// Quotes a CSV field when it holds a comma, quote or newline.
std::string csv_field(const std::string& text);

}  // namespace beamrail
