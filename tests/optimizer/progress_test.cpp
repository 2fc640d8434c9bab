// The progress line of batches (optimizer/progress): its text. done never
// exceeds total and the ETA is never negative (an optimization's line once read
// "200/8 designs ... ETA -7.7 s"), and it shows the best design given.
#include "optimizer/progress.hpp"

#include <gtest/gtest.h>

#include <regex>
#include <string>
#include <vector>

namespace beamrail {
namespace {

// The numbers of a progress line; false when the text does not have the line's
// form.
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
            "12/12 designs, 0 failed, best objective 0.0012, 7.2 s elapsed, "
            "ETA 0.0 s");
}

TEST(ProgressLine, BeforeTheFirstDesignTheEtaIsUnknownAndNoBestIsShown) {
  EXPECT_EQ(progress_line(0, 400, 0, "", 0.3),
            "0/400 designs, 0 failed, best -, 0.3 s elapsed, ETA -");
}

// The case the old line showed: 200 designs done of a "total" of 8 (NLopt
// calls); now the total is at least what was done, and the ETA is 0, not -7.7
// s.
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

}  // namespace
}  // namespace beamrail
