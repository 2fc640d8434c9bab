#include "optimizer/tables.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>

namespace beamrail {
namespace {

bool write_all(int fd, const std::string& text) {
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    done += static_cast<size_t>(n);
  }
  return true;
}

}  // namespace

std::string format_number(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  if (x == 0.0) return "0";  // also for -0
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
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

CsvWriter::~CsvWriter() {
  flush();
  if (fd_ >= 0) ::close(fd_);
}

bool CsvWriter::open(const std::filesystem::path& path, const std::vector<std::string>& header,
                     std::string* error) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    if (error) *error = "cannot write " + path.string() + ": " + std::strerror(errno);
    return false;
  }
  row(header);
  return flush();
}

bool CsvWriter::append(const std::filesystem::path& path, std::string* error) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd_ < 0) {
    if (error) *error = "cannot append to " + path.string() + ": " + std::strerror(errno);
    return false;
  }
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
  if (!buffer_.empty()) {
    ok_ = write_all(fd_, buffer_) && ok_;
    buffer_.clear();
  }
  if (sync) ok_ = (::fsync(fd_) == 0) && ok_;
  return ok_;
}

bool write_file_atomically(const std::filesystem::path& path, const std::string& text,
                           std::string* error) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    if (error) *error = "cannot write " + tmp.string() + ": " + std::strerror(errno);
    return false;
  }
  const bool ok = write_all(fd, text) && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
    if (error) *error = "cannot write " + path.string() + ": " + std::strerror(errno);
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

}  // namespace beamrail
