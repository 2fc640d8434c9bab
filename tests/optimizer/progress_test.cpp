// The progress line of batches (optimizer/progress): its text, and what an optimization shows on a
// terminal. The line counts designs against the design budget (starts x max_evaluations), so done
// never exceeds total and the ETA is never negative (it once read "200/8 designs ... ETA -7.7 s":
// NLopt calls counted against designs), and it shows the best feasible design found so far (it
// once read "best -" throughout).
#include "optimizer/batch/progress.hpp"

#include <gtest/gtest.h>
#include <pty.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <vector>

#include "tests/support/run_process.hpp"

#ifndef BEAMRAIL_EXECUTABLE
#error "BEAMRAIL_EXECUTABLE must name the beamrail binary"
#endif
#ifndef BEAMRAIL_STUDIES_DIR
#error "BEAMRAIL_STUDIES_DIR must name the studies/ directory"
#endif

namespace beamrail {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// The numbers of a progress line; false when the text does not have the line's form.
struct Parsed {
  long done = -1, total = -1, failures = -1;
  std::string best;
  double elapsed = -1.0;
  std::string eta;  // "-" or a number of seconds
};

bool parse(const std::string& line, Parsed* p) {
  static const std::regex form(
      R"(^(\d+)/(\d+) designs, (\d+) failed, best (.+), (\d+\.\d) s elapsed, ETA (-|-?\d+\.\d s)$)");
  std::smatch m;
  if (!std::regex_match(line, m, form)) return false;
  p->done = std::stol(m[1]), p->total = std::stol(m[2]), p->failures = std::stol(m[3]);
  p->best = m[4];
  p->elapsed = std::stod(m[5]);
  p->eta = m[6];
  return true;
}

TEST(ProgressLine, ShowsDoneOfTotalFailuresBestElapsedAndEta) {
  EXPECT_EQ(progress_line(3, 12, 1, "mass 16.32", 6.0),
            "3/12 designs, 1 failed, best mass 16.32, 6.0 s elapsed, ETA 18.0 s");
  EXPECT_EQ(progress_line(12, 12, 0, "objective 0.0012", 7.25),
            "12/12 designs, 0 failed, best objective 0.0012, 7.2 s elapsed, ETA 0.0 s");
}

TEST(ProgressLine, BeforeTheFirstDesignTheEtaIsUnknownAndNoBestIsShown) {
  EXPECT_EQ(progress_line(0, 400, 0, "", 0.3),
            "0/400 designs, 0 failed, best -, 0.3 s elapsed, ETA -");
}

// The case the old line showed: 200 designs done of a "total" of 8 (NLopt calls); now the total is
// at least what was done, and the ETA is 0, not -7.7 s.
TEST(ProgressLine, DoneNeverExceedsTotalAndTheEtaIsNeverNegative) {
  EXPECT_EQ(progress_line(200, 8, 3, "mass 16.32", 7.7),
            "200/200 designs, 3 failed, best mass 16.32, 7.7 s elapsed, ETA 0.0 s");
  for (long total : {0L, 1L, 7L, 100L})
    for (long done : {0L, 1L, 6L, 7L, 8L, 99L, 100L, 1000L})
      for (double elapsed : {0.0, 0.05, 3.0, 1e4}) {
        const std::string line = progress_line(done, total, 0, "mass 1", elapsed);
        SCOPED_TRACE(line);
        Parsed p;
        ASSERT_TRUE(parse(line, &p));
        EXPECT_LE(p.done, p.total);
        EXPECT_EQ(p.done, done);
        EXPECT_EQ(p.eta == "-", done == 0);
        if (p.eta != "-") {
          const double eta = std::stod(p.eta);
          EXPECT_GE(eta, 0.0);
          EXPECT_NEAR(eta, elapsed * static_cast<double>(std::max(total, done) - done) / done,
                      0.05 + 1e-9 * eta);
        }
      }
}

// --- What an optimization shows on a terminal ----------------------------------------------------

// Runs `beamrail run study -o out` with stdout and stderr on a pseudo-terminal (the progress line
// is shown only on one) and returns what it wrote there; *status is the exit status.
std::string run_on_a_terminal(const fs::path& dir, const std::string& study, int* status) {
  int master = -1;
  const std::string exe = BEAMRAIL_EXECUTABLE, where = dir.string();
  std::vector<std::string> storage{exe, "run", study, "-o", "out", "-j", "2"};
  std::vector<char*> argv;
  for (std::string& a : storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  winsize size{};
  size.ws_col = 200, size.ws_row = 40;
  const pid_t pid = forkpty(&master, nullptr, nullptr, &size);
  if (pid < 0) return "forkpty failed";
  if (pid == 0) {
    if (chdir(where.c_str()) != 0) _exit(127);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  std::string text;
  char buffer[4096];
  for (;;) {
    const ssize_t n = read(master, buffer, sizeof buffer);
    if (n > 0)
      text.append(buffer, static_cast<size_t>(n));
    else
      break;  // EIO once the child has closed the terminal
  }
  close(master);
  int wstatus = 0;
  waitpid(pid, &wstatus, 0);
  *status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1;
  return text;
}

// A gradient optimization (each NLopt call costs 2n + 1 = 3 designs) of a rod slow enough to draw
// several lines (about 2 s on two cores): every line counts within the budget of 2 starts x 30
// designs, its ETA is not negative, and once a feasible design is known the line names its mass.
TEST(ProgressLine, AnOptimizationOnATerminalCountsDesignsWithinItsBudgetAndShowsTheBest) {
  std::string pattern = (fs::temp_directory_path() / "beamrail_progress_XXXXXX").string();
  ASSERT_NE(mkdtemp(pattern.data()), nullptr);
  const fs::path dir = pattern;
  Json s = Json::parse(testing::read_text(fs::path(BEAMRAIL_STUDIES_DIR) / "min_mass_rod.json"));
  s["scene"]["beams"][0]["segments"] = 400;  // with 40 modes, about 30 ms a design
  s["analyses"][0]["modes"] = 40;
  s["study"]["algorithm"] = "LD_SLSQP";
  s["study"]["gradient"] = "fd";  // central differences: 3 designs per call
  s["study"]["max_evaluations"] = 30;
  s["study"]["starts"] = 2;
  std::ofstream(dir / "rod.json") << s.dump(2);
  int status = -1;
  const std::string text = run_on_a_terminal(dir, "rod.json", &status);
  const Json summary =
      Json::parse(testing::read_text(dir / "out" / "summary.json"), nullptr, false);
  fs::remove_all(dir);
  ASSERT_EQ(status, 0) << text;

  // The lines are drawn over each other: "\r<line>\033[K".
  std::vector<Parsed> lines;
  size_t at = 0;
  while ((at = text.find('\r', at)) != std::string::npos) {
    const size_t end = text.find("\033[K", at);
    if (end == std::string::npos) break;
    const std::string line = text.substr(at + 1, end - at - 1);
    at = end;
    Parsed p;
    if (!parse(line, &p)) continue;
    std::printf("%s\n", line.c_str());
    lines.push_back(p);
  }
  ASSERT_GE(lines.size(), 2u) << "too few progress lines to test (the run took "
                              << summary.value("wall_seconds", 0.0) << " s):\n"
                              << text;
  for (const Parsed& p : lines) {
    EXPECT_LE(p.done, p.total);
    EXPECT_LE(p.total, 60);
    EXPECT_NE(p.eta.front(), '-') << "done " << p.done;  // designs are done: the ETA is known
    EXPECT_GE(std::stod(p.eta), 0.0);
    EXPECT_EQ(p.failures, 0);
  }
  // The start point (d = 50 mm, 17.4 kg) is feasible and evaluated first: every line shows a best.
  const std::regex best(R"(mass \d+\.\d+.*)");
  for (const Parsed& p : lines) EXPECT_TRUE(std::regex_match(p.best, best)) << p.best;
  // The totals only fall (a start that stops early gives back its budget left) and the counts only
  // rise; the best mass only falls.
  for (size_t i = 1; i < lines.size(); ++i) {
    EXPECT_LE(lines[i].total, lines[i - 1].total);
    EXPECT_GE(lines[i].done, lines[i - 1].done);
    EXPECT_LE(std::stod(lines[i].best.substr(5)), std::stod(lines[i - 1].best.substr(5)));
  }
  // The designs of history.csv are at most the budget.
  EXPECT_LE(summary["designs_in_history"].get<long>(), 60);
}

}  // namespace
}  // namespace beamrail
