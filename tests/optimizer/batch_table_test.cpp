// The table of a batch at the library level (optimizer/output/batch_table.hpp): rows appended by
// many threads end whole and, after finalize, sorted by their numeric keys, each key once; a
// resumed table gives back its whole rows and drops an unfinished last line; a table of other
// columns is not resumed; quoted fields read back as written.
#include "optimizer/output/batch_table.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "optimizer/output/tables.hpp"

namespace beamrail {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> lines_of(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class BatchTableTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "beamrail_table_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path dir_;
};

TEST_F(BatchTableTest, RowsFromManyThreadsEndSortedByTheirKeysEachOnce) {
  BatchTable table;
  std::vector<CsvRow> existing;
  std::string error;
  const fs::path path = dir_ / "samples.csv";
  ASSERT_EQ(table.open(path, {"start", "index", "note"}, false, &existing, &error),
            BatchTable::Opened::kOk)
      << error;
  const int threads = 4, per_thread = 60;  // keys (start, index): start = i % 3, index = -i
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&, t] {
      for (int k = 0; k < per_thread; ++k) {
        const int i = k * threads + t;
        EXPECT_TRUE(
            table.append({std::to_string(i % 3), std::to_string(-i), "a, \"quoted\" note"}));
      }
    });
  for (std::thread& t : pool) t.join();
  ASSERT_TRUE(table.append({"0", "-0", "the same key again: dropped"}));
  ASSERT_TRUE(table.finalize({0, 1}, &error)) << error;
  const std::vector<std::string> lines = lines_of(path);
  ASSERT_EQ(lines.size(), 1u + threads * per_thread);
  EXPECT_EQ(lines[0], "start,index,note");
  double last_start = -1, last_index = 0;
  for (size_t k = 1; k < lines.size(); ++k) {
    const CsvRow row = parse_csv_line(lines[k]);
    ASSERT_EQ(row.size(), 3u) << lines[k];
    EXPECT_EQ(row[2], "a, \"quoted\" note");
    const double start = std::stod(row[0]), index = std::stod(row[1]);
    EXPECT_TRUE(start > last_start || (start == last_start && index > last_index)) << lines[k];
    last_start = start, last_index = index;
  }
}

TEST_F(BatchTableTest, AResumedTableGivesBackItsWholeRowsAndDropsAnUnfinishedLine) {
  const fs::path path = dir_ / "samples.csv";
  std::ofstream(path) << "index,value\n2,0.5\n0,\"1,5\"\n1,2";  // the last line unfinished
  BatchTable table;
  std::vector<CsvRow> existing;
  std::string error;
  ASSERT_EQ(table.open(path, {"index", "value"}, true, &existing, &error), BatchTable::Opened::kOk)
      << error;
  ASSERT_EQ(existing.size(), 2u);
  EXPECT_EQ(existing[0], (CsvRow{"2", "0.5"}));
  EXPECT_EQ(existing[1], (CsvRow{"0", "1,5"}));
  ASSERT_TRUE(table.append({"1", "3"}));
  ASSERT_TRUE(table.finalize({0}, &error)) << error;
  EXPECT_EQ(lines_of(path), (std::vector<std::string>{"index,value", "0,\"1,5\"", "1,3", "2,0.5"}));

  BatchTable other;
  EXPECT_EQ(other.open(path, {"index", "mass"}, true, &existing, &error),
            BatchTable::Opened::kOtherColumns);
  EXPECT_NE(error.find(path.string()), std::string::npos) << error;
  EXPECT_EQ(lines_of(path).size(), 4u);  // left as it was
}

// write_rows hands rows to the system in pieces that end at a row's end and lie within one
// 4 KiB page of the file, or are the one row that crosses into the next page (a write killed
// outright stops between pages, never within one): each write is read back as one packet of a
// packet-mode pipe. Rows of 1 to 300 bytes from a file
// offset of 1000; then rows longer than a page into a file, read back the same.
TEST(WriteRows, PiecesEndAtRowEndsWithinOnePageOfTheFile) {
  std::mt19937 random(7);
  std::string text;
  while (text.size() < 40000) {
    const size_t length = std::uniform_int_distribution<size_t>(1, 300)(random);
    text += std::string(length - 1, static_cast<char>('a' + text.size() % 26)) + "\n";
  }
  int fds[2];
  ASSERT_EQ(::pipe2(fds, O_DIRECT), 0);
  std::vector<std::string> pieces;
  std::thread reader([&] {
    char buffer[4096];
    for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) > 0;)
      pieces.emplace_back(buffer, static_cast<size_t>(n));
  });
  const off_t offset = 1000;
  EXPECT_TRUE(write_rows(fds[1], text, offset));
  ::close(fds[1]);
  reader.join();
  ::close(fds[0]);
  std::string joined;
  off_t at = offset;
  for (const std::string& piece : pieces) {
    ASSERT_FALSE(piece.empty());
    EXPECT_EQ(piece.back(), '\n') << "a piece at " << at << " ends within a row";
    // Within a page, or one row that does not fit in the rest of its page.
    if (at / 4096 != (at + static_cast<off_t>(piece.size()) - 1) / 4096) {
      EXPECT_EQ(piece.find('\n'), piece.size() - 1)
          << "a piece at " << at << " of " << piece.size() << " bytes crosses a page";
    }
    at += static_cast<off_t>(piece.size());
    joined += piece;
  }
  EXPECT_EQ(joined, text);
  EXPECT_GT(pieces.size(), text.size() / 4096);

  const fs::path file = fs::temp_directory_path() / ("write_rows_" + std::to_string(::getpid()));
  std::string long_rows = "short\n" + std::string(9000, 'x') + "\n" + text.substr(0, 5000) +
                          std::string(4095, 'y') + "\n";
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_TRUE(write_rows(fd, std::string(123, 'h') + "\n", 0));
  ASSERT_TRUE(write_rows(fd, long_rows, 124));
  ::close(fd);
  std::ifstream in(file, std::ios::binary);
  std::stringstream back;
  back << in.rdbuf();
  EXPECT_EQ(back.str(), std::string(123, 'h') + "\n" + long_rows);
  fs::remove(file);
}

}  // namespace
}  // namespace beamrail
