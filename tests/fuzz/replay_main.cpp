// A short fuzz run with any compiler: feeds LLVMFuzzerTestOneInput (study_fuzz.cpp) every file of
// a corpus, then random mutations of them (structural changes as in json_mutator.hpp, byte edits,
// dictionary tokens, splices) from a fixed seed, for a bounded number of runs and time. A crash,
// an abort from a broken contract or an input that runs longer than --input-seconds saves the
// input that caused it and fails.
//
//   study_fuzz_replay [--runs N] [--seconds S] [--seed K] [--input-seconds T] [--dict FILE]
//                     [--crash FILE] CORPUS_DIR_OR_FILE...
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/fuzz/json_mutator.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

namespace fs = std::filesystem;
using Bytes = std::string;

// The input being run, for the signal handler.
const char* g_input = nullptr;
size_t g_input_size = 0;
char g_crash_path[4096] = "study_fuzz_replay_crash.json";

void write_all(int fd, const char* p, size_t n) {
  while (n > 0) {
    const ssize_t w = write(fd, p, n);
    if (w <= 0) return;
    p += w, n -= static_cast<size_t>(w);
  }
}

// Saves the input that failed, then dies of the signal (only async-signal-safe calls).
void on_failure(int sig) {
  const char* what = sig == SIGALRM ? "study_fuzz_replay: input ran too long; saved to "
                                    : "study_fuzz_replay: input crashed; saved to ";
  write_all(2, what, std::strlen(what));
  write_all(2, g_crash_path, std::strlen(g_crash_path));
  write_all(2, "\n", 1);
  const int fd = open(g_crash_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd >= 0 && g_input) write_all(fd, g_input, g_input_size);
  if (fd >= 0) close(fd);
  signal(SIGABRT, SIG_DFL);
  abort();
}

void run_one(const Bytes& input, unsigned input_seconds) {
  g_input = input.data();
  g_input_size = input.size();
  alarm(input_seconds);
  LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(input.data()), input.size());
  alarm(0);
  g_input = nullptr;
}

Bytes read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Reads a libFuzzer dictionary: lines name="value" with \\, \" and \xNN escapes.
std::vector<Bytes> read_dictionary(const fs::path& p) {
  std::vector<Bytes> out;
  std::istringstream lines(read_bytes(p));
  for (std::string line; std::getline(lines, line);) {
    const size_t open = line.find('"'), close = line.rfind('"');
    if (line.empty() || line[0] == '#' || open == std::string::npos || close <= open) continue;
    Bytes token;
    for (size_t i = open + 1; i < close; ++i) {
      if (line[i] != '\\' || i + 1 >= close) {
        token += line[i];
      } else if (line[i + 1] == 'x' && i + 3 < close) {
        token += static_cast<char>(std::strtol(line.substr(i + 2, 2).c_str(), nullptr, 16));
        i += 3;
      } else {
        token += line[++i];
      }
    }
    out.push_back(token);
  }
  return out;
}

using beamrail::fuzz::Random;

// One random edit of the kinds libFuzzer makes.
void mutate(Bytes& b, const std::vector<Bytes>& corpus, const std::vector<Bytes>& dict,
            Random& rng) {
  static const char kInteresting[] = "{}[]\",:0-1e.9\\\x00\xff\xc3 ";
  // Half the time a structural change of a document that still parses.
  if (rng.below(2) == 0 && beamrail::fuzz::mutate_json(b, rng)) return;
  const size_t at = rng.below(b.size() + 1);
  switch (rng.below(8)) {
    case 0:  // flip a bit
      if (!b.empty()) b[rng.below(b.size())] ^= static_cast<char>(1u << rng.below(8));
      break;
    case 1:  // set a byte to a structural or odd character
      if (!b.empty()) b[rng.below(b.size())] = kInteresting[rng.below(sizeof kInteresting - 1)];
      break;
    case 2:  // insert one
      b.insert(at, 1, kInteresting[rng.below(sizeof kInteresting - 1)]);
      break;
    case 3:  // erase a range
      if (!b.empty()) b.erase(rng.below(b.size()), 1 + rng.below(16));
      break;
    case 4:  // duplicate a range
      if (!b.empty()) {
        const size_t from = rng.below(b.size());
        b.insert(at, b.substr(from, 1 + rng.below(64)));
      }
      break;
    case 5:  // insert or overwrite with a dictionary token
    case 6:
      if (!dict.empty()) {
        const Bytes& t = dict[rng.below(dict.size())];
        if (rng.below(2) || at + t.size() > b.size())
          b.insert(at, t);
        else
          b.replace(at, t.size(), t);
      }
      break;
    default: {  // splice in a piece of another corpus file
      const Bytes& other = corpus[rng.below(corpus.size())];
      if (!other.empty()) {
        const size_t from = rng.below(other.size());
        b.replace(at, rng.below(32), other.substr(from, 1 + rng.below(256)));
      }
    }
  }
  // Numbers: replace a digit run by an extreme value now and then.
  if (rng.below(16) == 0) {
    static const char* kNumbers[] = {
        "0",   "-0", "1e308", "1e-320", "-1", "100000", "1e15", "4294967296", "9223372036854775807",
        "0.5", "3"};
    const size_t d = b.find_first_of("0123456789", rng.below(b.size() + 1));
    if (d != Bytes::npos) {
      const size_t end = b.find_first_not_of("0123456789.eE+-", d);
      b.replace(d, (end == Bytes::npos ? b.size() : end) - d,
                kNumbers[rng.below(sizeof kNumbers / sizeof *kNumbers)]);
    }
  }
}

int usage() {
  std::cerr << "usage: study_fuzz_replay [--runs N] [--seconds S] [--seed K] [--input-seconds T]"
               " [--dict FILE] [--crash FILE] CORPUS...\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  long runs = 100000;
  double seconds = 20.0;
  uint64_t seed = 1;
  unsigned input_seconds = 10;
  std::vector<Bytes> dict;
  std::vector<fs::path> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--runs" && has_value) {
      runs = std::atol(argv[++i]);
    } else if (a == "--seconds" && has_value) {
      seconds = std::atof(argv[++i]);
    } else if (a == "--seed" && has_value) {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else if (a == "--input-seconds" && has_value) {
      input_seconds = static_cast<unsigned>(std::atoi(argv[++i]));
    } else if (a == "--dict" && has_value) {
      dict = read_dictionary(argv[++i]);
    } else if (a == "--crash" && has_value) {
      std::snprintf(g_crash_path, sizeof g_crash_path, "%s", argv[++i]);
    } else if (!a.empty() && a[0] == '-') {
      return usage();
    } else if (fs::is_directory(a)) {
      for (const auto& e : fs::directory_iterator(a))
        if (e.is_regular_file()) files.push_back(e.path());
    } else {
      files.push_back(a);
    }
  }
  if (files.empty()) return usage();
  std::sort(files.begin(), files.end());
  for (int sig : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGALRM}) signal(sig, on_failure);

  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  std::vector<Bytes> corpus;
  for (const fs::path& f : files) {
    corpus.push_back(read_bytes(f));
    run_one(corpus.back(), input_seconds);
  }
  const double corpus_seconds = elapsed();

  Random rng(seed);
  long done = 0;
  for (; done < runs && elapsed() < seconds; ++done) {
    Bytes input = corpus[rng.below(corpus.size())];
    for (size_t k = 1 + rng.below(4); k > 0; --k) mutate(input, corpus, dict, rng);
    run_one(input, input_seconds);
  }
  std::cout << "study_fuzz_replay: " << corpus.size() << " corpus files in " << corpus_seconds
            << " s, " << done << " mutated inputs (seed " << seed << ") in "
            << elapsed() - corpus_seconds << " s: no failure\n";
  return 0;
}
