#include "optimizer/output/tables.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>

namespace beamrail {

bool write_all(int fd, const char* text, size_t size) {
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, text + done, size - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    done += static_cast<size_t>(n);
  }
  return true;
}

bool write_all(int fd, const std::string& text) { return write_all(fd, text.data(), text.size()); }

// A process killed outright (SIGKILL) can stop a write between two pages of the file (Linux
// checks for a fatal signal before it copies each page), which cut a row in
// ResultsFolder.AKilledSingleRunLeavesItsRowsOnDisk once in CI: hence pieces within a page. A
// row longer than a page is written whole in one piece, and can still be cut.
bool write_rows(int fd, const std::string& text, off_t offset) {
  constexpr size_t kPage = 4096;
  size_t done = 0;
  while (done < text.size()) {
    const size_t page_end = done + (kPage - static_cast<size_t>(offset + done) % kPage);
    size_t end = text.size();
    if (page_end < text.size()) {
      const size_t last = text.rfind('\n', page_end - 1);
      if (last != std::string::npos && last >= done) {
        end = last + 1;
      } else {
        const size_t next = text.find('\n', page_end);
        if (next != std::string::npos) end = next + 1;
      }
    }
    if (!write_all(fd, text.data() + done, end - done)) return false;
    done = end;
  }
  return true;
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string write_error(const std::filesystem::path& path, int errno_value) {
  return "cannot write " + path.string() + ": " + std::strerror(errno_value);
}

CsvWriter::~CsvWriter() {
  flush();
  if (fd_ >= 0) ::close(fd_);
}

void CsvWriter::fail(const char* what) {
  const int e = errno;
  if (error_.empty()) error_ = std::string(what) + " " + path_.string() + ": " + std::strerror(e);
  ok_ = false;
}

bool CsvWriter::open(const std::filesystem::path& path, const std::vector<std::string>& header,
                     std::string* error, bool staged) {
  path_ = path;
  file_ = staged ? std::filesystem::path(path.string() + ".partial") : path;
  fd_ = ::open(file_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    fail("cannot write");
    if (error) *error = error_;
    return false;
  }
  row(header);
  if (flush()) return true;
  if (error) *error = error_;
  return false;
}

bool CsvWriter::append(const std::filesystem::path& path, std::string* error) {
  path_ = file_ = path;
  fd_ = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd_ < 0) {
    fail("cannot append to");
    if (error) *error = error_;
    return false;
  }
  written_ = ::lseek(fd_, 0, SEEK_END);
  return true;
}

void CsvWriter::row(const std::vector<std::string>& fields) {
  for (size_t i = 0; i < fields.size(); ++i) {
    if (i) buffer_ += ',';
    buffer_ += csv_field(fields[i]);
  }
  buffer_ += '\n';
  if (buffer_.size() > (1 << 16)) flush();
}

void CsvWriter::row(const std::vector<double>& values) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (i) buffer_ += ',';
    buffer_ += format_number(values[i]);
  }
  buffer_ += '\n';
  if (buffer_.size() > (1 << 16)) flush();
}

bool CsvWriter::flush(bool sync) {
  if (fd_ < 0) return false;
  if (!ok_) {
    buffer_.clear();
    return false;
  }
  if (!buffer_.empty()) {
    if (write_rows(fd_, buffer_, written_)) {
      written_ += static_cast<off_t>(buffer_.size());
    } else {
      fail("cannot write");
      // Cut off what reached the file of the rows just written: the table ends with a whole row.
      if (::ftruncate(fd_, written_) != 0) error_ += " (and the part of a row written stays)";
    }
    buffer_.clear();
  }
  if (ok_ && sync && ::fsync(fd_) != 0) fail("cannot write");
  return ok_;
}

bool CsvWriter::commit(std::string* error) {
  flush();
  if (fd_ >= 0 && ::close(fd_) != 0 && ok_) fail("cannot write");
  fd_ = -1;
  // After a write error too: the rows that were written are whole, and they are this run's.
  if (file_ != path_ && !file_.empty()) {
    if (std::rename(file_.c_str(), path_.c_str()) == 0) {
      file_ = path_;
    } else {
      if (error_.empty()) error_ = write_error(path_, errno);
      ok_ = false;
    }
  }
  if (!ok_ && error) *error = error_;
  return ok_;
}

bool write_file_atomically(const std::filesystem::path& path, const std::string& text,
                           std::string* error) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    if (error) *error = write_error(tmp, errno);
    return false;
  }
  int e = 0;
  if (!write_all(fd, text) || ::fsync(fd) != 0) e = errno;
  if (::close(fd) != 0 && e == 0) e = errno;
  if (e == 0 && std::rename(tmp.c_str(), path.c_str()) != 0) e = errno;
  if (e != 0) {
    if (error) *error = write_error(path, e);
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

}  // namespace beamrail
