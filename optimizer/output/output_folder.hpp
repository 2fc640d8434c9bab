// The results folder of one `beamrail run`: held by the run (an exclusive lock on
// .beamrail.lock in it, so that a second run into the same folder is refused instead of mixing its
// rows into the first one's tables), with the study that defines its tables recorded in it
// (resolved_study.json, which --resume compares with the study it is given), and marked
// incomplete while the run lasts (summary.json with status "running", replaced by the run's own
// summary at its end).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "optimizer/study/study.hpp"

namespace beamrail {

class OutputFolder {
 public:
  OutputFolder() = default;
  ~OutputFolder();  // releases the lock
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  // Creates the folder when needed and takes its lock. False with *error naming the folder and
  // the reason: it cannot be created or written, or another run holds it. On a file system
  // without locks it goes on without one, saying so in *warning (else left as it was).
  bool acquire(const std::filesystem::path& directory, std::string* error, std::string* warning);

  // Records the study (resolved_study.json) and replaces summary.json by the "running" marker.
  // False with *error naming the file and the reason.
  bool start(const Study& study, std::string* error) const;

  const std::filesystem::path& path() const { return directory_; }

 private:
  std::filesystem::path directory_;
  int fd_ = -1;
};

// The name of the lock file and of the study record in a results folder.
inline constexpr const char* kLockFile = ".beamrail.lock";
inline constexpr const char* kStudyRecord = "resolved_study.json";

// What defines a study's results: the study as read, its scene file inlined, without its
// "description" and "outputs" (the command line, such as -j, is not part of it).
nlohmann::json study_content(const Study& study);

// Whether the batch table `table` in `directory` may be continued by this study: "" when it may
// (or when it holds no rows yet), else the reason and what to do.
std::string resume_refusal(const Study& study, const std::filesystem::path& directory,
                           const std::string& table);

}  // namespace beamrail
