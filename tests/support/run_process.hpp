// Runs a program (the beamrail binary) from a test: fork/exec in a given directory, stdout and
// stderr captured to files, with a time limit so that a hang fails like a crash. A started process
// can also be left running and killed, to test what an interrupted run leaves behind, and started
// with resource limits (file size, address space).
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace beamrail::testing {

struct ProcessResult {
  bool exited = false;  // false: killed by a signal or by the time limit
  int status = -1;      // exit status when exited
  int signal = 0;       // terminating signal when killed
  std::string how;      // how it ended, for failure messages
  std::string out, err;
};

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Resource limits of a started process (-1: inherited).
struct Limits {
  long file_size = -1;      // RLIMIT_FSIZE [bytes]; SIGXFSZ is then ignored, so that a write
                            // past it fails with EFBIG instead of killing the process
  long address_space = -1;  // RLIMIT_AS [bytes]
};

// A process started in `dir` with stdout and stderr going to dir/.stdout and dir/.stderr
// (the names can be changed with `tag`).
class Process {
 public:
  Process(const std::string& exe, const std::vector<std::string>& args,
          const std::filesystem::path& dir, const std::string& tag = "", Limits limits = {})
      : out_path_((dir / (".stdout" + tag)).string()),
        err_path_((dir / (".stderr" + tag)).string()) {
    const std::string where = dir.string();
    std::vector<std::string> storage{exe};
    storage.insert(storage.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : storage) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_ = fork();
    if (pid_ == 0) {  // only async-signal-safe calls until exec
      const int out = open(out_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int err = open(err_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (out < 0 || err < 0 || chdir(where.c_str()) != 0) _exit(127);
      dup2(out, 1);
      dup2(err, 2);
      if (limits.file_size >= 0) {
        const rlimit r{static_cast<rlim_t>(limits.file_size),
                       static_cast<rlim_t>(limits.file_size)};
        signal(SIGXFSZ, SIG_IGN);
        if (setrlimit(RLIMIT_FSIZE, &r) != 0) _exit(126);
      }
      if (limits.address_space >= 0) {
        const rlimit r{static_cast<rlim_t>(limits.address_space),
                       static_cast<rlim_t>(limits.address_space)};
        if (setrlimit(RLIMIT_AS, &r) != 0) _exit(126);
      }
      execv(exe.c_str(), argv.data());
      _exit(127);
    }
  }
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;
  ~Process() {
    if (running()) kill(SIGKILL), wait(std::chrono::seconds(10));
  }

  bool started() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  bool running() const { return pid_ > 0 && !done_; }

  // True while the process has not ended (reaps it when it has).
  bool alive() {
    if (!running()) return false;
    const pid_t w = waitpid(pid_, &status_, WNOHANG);
    if (w == pid_ || w < 0) done_ = true;
    return !done_;
  }

  void kill(int sig) {
    if (running()) ::kill(pid_, sig);
  }

  // Waits for the end, at most `limit` (then kills it: a hang ends like a crash).
  ProcessResult wait(std::chrono::milliseconds limit) {
    ProcessResult r;
    if (pid_ <= 0) {
      r.how = "fork failed";
      return r;
    }
    const auto deadline = std::chrono::steady_clock::now() + limit;
    bool timed_out = false;
    while (alive()) {
      if (std::chrono::steady_clock::now() > deadline) {
        ::kill(pid_, SIGKILL);
        waitpid(pid_, &status_, 0);
        done_ = true;
        timed_out = true;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    r.exited = !timed_out && WIFEXITED(status_);
    if (timed_out) {
      r.how = "killed after the time limit (hang)";
    } else if (r.exited) {
      r.status = WEXITSTATUS(status_);
      r.how = "exit status " + std::to_string(r.status);
    } else if (WIFSIGNALED(status_)) {
      r.signal = WTERMSIG(status_);
      r.how = "terminated by signal " + std::to_string(r.signal);
    } else {
      r.how = "ended abnormally";
    }
    r.out = read_text(out_path_);
    r.err = read_text(err_path_);
    return r;
  }

 private:
  std::string out_path_, err_path_;
  pid_t pid_ = -1;
  int status_ = 0;
  bool done_ = false;
};

// Runs a program to its end (at most `limit`).
inline ProcessResult run_process(const std::string& exe, const std::vector<std::string>& args,
                                 const std::filesystem::path& dir,
                                 std::chrono::milliseconds limit = std::chrono::seconds(60),
                                 Limits limits = {}) {
  Process p(exe, args, dir, "", limits);
  return p.wait(limit);
}

}  // namespace beamrail::testing
