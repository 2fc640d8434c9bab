#include "optimizer/output/output_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "optimizer/output/tables.hpp"
#include "optimizer/output/version.hpp"
#include "optimizer/run/status.hpp"

namespace beamrail {
namespace {

namespace fs = std::filesystem;

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Whether the table holds a header line and at least one row line after it.
bool has_rows(const fs::path& table) {
  std::ifstream in(table, std::ios::binary);
  int lines = 0;
  for (char c; lines < 2 && in.get(c);) lines += c == '\n';
  return lines >= 2;
}

}  // namespace

OutputFolder::~OutputFolder() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

bool OutputFolder::acquire(const fs::path& directory, std::string* error, std::string* warning) {
  directory_ = directory;
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (ec || !fs::is_directory(directory)) {
    *error = "cannot create the output folder " + directory.string() + ": " +
             (ec ? ec.message() : std::string("a file of that name is in the way"));
    return false;
  }
  const fs::path lock = directory / kLockFile;
  fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    *error = "cannot use the output folder " + directory.string() + ": " + write_error(lock, errno);
    return false;
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int e = errno;
    if (e == ENOLCK || e == EOPNOTSUPP || e == ENOSYS) {
      // A file system without locks (some network file systems): run, but say what is missing.
      *warning = "cannot lock " + lock.string() + " (" + std::strerror(e) +
                 "): a second run into " + directory.string() + " would not be refused";
      return true;
    }
    if (e == EWOULDBLOCK) {
      std::string holder = read_file(lock);
      while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
      *error = "the output folder " + directory.string() + " is in use by another beamrail run" +
               (holder.empty() ? std::string() : " (process " + holder + ")") +
               ": wait for it to end, or choose another folder with -o";
    } else {
      *error = "cannot lock " + lock.string() + ": " + std::strerror(e);
    }
    ::close(fd_);
    fd_ = -1;
    return false;
  }
  // Names this process to a run that is refused.
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, pid.data(), pid.size(), 0) < 0) {
    *error = "cannot use the output folder " + directory.string() + ": " + write_error(lock, errno);
    return false;
  }
  return true;
}

bool OutputFolder::start(const Study& study, std::string* error) const {
  nlohmann::json running;
  running["study"] = study.name;
  running["file"] = study.file;
  running["beamrail_version"] = kVersion;
  if (study.design) {
    switch (study.design->type) {
      case DesignStudy::Type::kSweep:
        running["type"] = "sweep";
        break;
      case DesignStudy::Type::kOptimize:
        running["type"] = "optimize";
        break;
      case DesignStudy::Type::kWorkPrecision:
        running["type"] = "work_precision";
        break;
      case DesignStudy::Type::kSensitivity:
        running["type"] = "sensitivity";
        break;
    }
  }
  running["status"] = run_status_name(RunStatus::kRunning);
  running["message"] =
      "a run started writing this folder and has not finished (it is running, or it was killed): "
      "the tables may be incomplete";
  running["pid"] = ::getpid();
  return write_file_atomically(directory_ / "summary.json", running.dump(2) + "\n", error) &&
         write_file_atomically(directory_ / kStudyRecord, study.document.dump(2) + "\n", error);
}

nlohmann::json study_content(const Study& study) {
  nlohmann::json content = study.document;
  if (content.is_object()) content.erase("description");
  if (content.is_object()) content.erase("outputs");  // what is written besides, not the results
  return content;
}

std::string resume_refusal(const Study& study, const fs::path& directory,
                           const std::string& table) {
  const fs::path rows = directory / table;
  if (!has_rows(rows)) return "";  // nothing to mix with
  const std::string what_to_do =
      "; run without --resume to start over (the tables there are replaced), or choose another "
      "folder with -o";
  const fs::path record = directory / kStudyRecord;
  std::error_code ec;
  if (!fs::exists(record, ec))
    return "cannot resume: " + rows.string() + " has no record of the study that wrote it (" +
           record.string() + " is missing)" + what_to_do;
  nlohmann::json before = nlohmann::json::parse(read_file(record), nullptr, false);
  if (before.is_discarded() || !before.is_object())
    return "cannot resume: " + record.string() + " is not the record of a study" + what_to_do;
  before.erase("description");
  before.erase("outputs");
  const nlohmann::json now = study_content(study);
  if (before == now) return "";
  const nlohmann::json patch = nlohmann::json::diff(before, now);
  const std::string where = patch.empty() ? "/" : patch[0].value("path", "/");
  return "cannot resume: this study differs from the one that wrote " + rows.string() +
         " (first difference at " + (where.empty() ? "/" : where) + ")" + what_to_do;
}

}  // namespace beamrail
