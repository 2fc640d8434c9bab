#include "optimizer/batch/mpi_job.hpp"

#include <cstdlib>

#include "optimizer/batch/executor.hpp"

#ifdef BEAMRAIL_MPI
#include <mpi.h>
#include <time.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/analysis/stop_request.hpp"
#include "optimizer/batch/wire.hpp"
#endif

namespace beamrail {

namespace {
MpiJob* current_job = nullptr;
}  // namespace

MpiJob* mpi_job() { return current_job; }

#ifndef BEAMRAIL_MPI

bool mpi_available() { return false; }
MpiJob::MpiJob(int*, char***) { current_job = this; }
MpiJob::~MpiJob() { current_job = nullptr; }
int MpiJob::serve() { return 0; }
std::unique_ptr<BatchExecutor> MpiJob::executor(int threads) {
  return std::make_unique<ThreadExecutor>(threads);
}

#else

bool mpi_available() { return true; }

namespace {

// Message tags: rank 0 sends the study, designs and the stop; the others send outcomes.
constexpr int kTagStudy = 1, kTagWork = 2, kTagResult = 3, kTagStop = 4;

std::vector<char> pack_result(long index, const DesignOutcome& o) {
  Packer p;
  p.put<int64_t>(index);
  p.put_outcome(o);
  return std::move(p.bytes);
}

long unpack_result(const std::vector<char>& bytes, DesignOutcome* o) {
  Unpacker u(bytes);
  const long index = static_cast<long>(u.get<int64_t>());
  *o = u.get_outcome();
  return index;
}

// Receives the message that MPI_Iprobe found.
std::vector<char> receive(const MPI_Status& probed) {
  int count = 0;
  MPI_Get_count(&probed, MPI_BYTE, &count);
  std::vector<char> bytes(static_cast<size_t>(count));
  MPI_Recv(bytes.data(), count, MPI_BYTE, probed.MPI_SOURCE, probed.MPI_TAG, MPI_COMM_WORLD,
           MPI_STATUS_IGNORE);
  return bytes;
}

void send(const std::vector<char>& bytes, int rank, int tag) {
  MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, rank, tag, MPI_COMM_WORLD);
}

// CPU time of the calling thread [s]: what scheduling costs rank 0, not counting the time the
// system gives its cores to other threads (on an oversubscribed machine, most of the wall time).
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Polling waits: MPI's blocking receives spin on a core, which a rank's evaluating threads need.
// A loop that found nothing sleeps, twice as long each time up to `longest`.
class Backoff {
 public:
  explicit Backoff(std::chrono::microseconds longest) : longest_(longest) {}
  void reset() { wait_ = std::chrono::microseconds(10); }
  std::chrono::microseconds next() {
    const auto w = wait_;
    wait_ = std::min(longest_, 2 * wait_);
    return w;
  }

 private:
  std::chrono::microseconds longest_, wait_{10};
};

// Rank 0's executor: designs go to the other ranks, `threads` + 1 ahead per rank, and to rank 0's
// own `threads` threads, in index order as each asks for more.
class MpiExecutor : public BatchExecutor {
 public:
  MpiExecutor(MpiJob& job, int threads) : job_(job), threads_(threads) {}
  int ranks() const override { return job_.size(); }
  int threads() const override { return threads_; }
  ExecutorStats stats() const override { return stats_; }

  void evaluate(const DesignEvaluator& evaluator, const std::vector<Design>& designs,
                const DesignDone& done) override {
    const int size = job_.size();
    stats_.designs_per_rank.resize(size, 0);
    double scheduling = 0.0, polling = 0.0;  // CPU seconds
    if (!job_.study_sent) {
      const Study& study = evaluator.study();
      Packer p;
      p.put<int32_t>(threads_);
      p.put_string(study.file);
      p.put_string(study.directory.string());
      p.put_string(study.document.dump());
      for (int r = 1; r < size; ++r) send(p.bytes, r, kTagStudy);
      job_.study_sent = true;
    }
    const long n = static_cast<long>(designs.size());
    std::atomic<long> next(0);
    std::atomic<bool> stopped(false);
    std::mutex done_mutex;
    // The next design to start, -1 when none is left or the batch stops.
    auto take = [&]() -> long {
      if (stopped || stop_requested()) return -1;
      const long i = next++;
      return i < n ? i : -1;
    };
    auto deliver = [&](int rank, long i, const DesignOutcome& o) {
      const std::lock_guard<std::mutex> lock(done_mutex);
      ++stats_.designs_per_rank[rank];
      if (!done(i, o)) stopped = true;
    };
    std::vector<std::thread> pool;
    for (int t = 0; t < threads_; ++t)
      pool.emplace_back([&] {
        for (long i = take(); i >= 0; i = take())
          deliver(0, i, evaluate_design(evaluator, designs[i]));
      });

    std::vector<int> ahead(size, 0);
    long pending = 0;  // designs sent and not back yet
    bool exhausted = false;
    Backoff backoff(std::chrono::microseconds(1000));
    while (true) {
      const double busy = thread_cpu_seconds();
      const long pending_before = pending;
      for (int r = 1; r < size && !exhausted; ++r)
        while (ahead[r] < threads_ + 1) {
          const long i = take();
          if (i < 0) {
            exhausted = true;
            break;
          }
          Packer p;
          p.put<int64_t>(i);
          p.put_doubles(designs[i]);
          send(p.bytes, r, kTagWork);
          ++ahead[r];
          ++pending;
        }
      int found = 0;
      MPI_Status probed;
      MPI_Iprobe(MPI_ANY_SOURCE, kTagResult, MPI_COMM_WORLD, &found, &probed);
      if (found) {
        DesignOutcome o;
        const long i = unpack_result(receive(probed), &o);
        --ahead[probed.MPI_SOURCE];
        --pending;
        scheduling += thread_cpu_seconds() - busy;
        deliver(probed.MPI_SOURCE, i, o);
        backoff.reset();
        continue;
      }
      // A loop that sent nothing and found nothing is polling, not scheduling a design.
      (pending != pending_before ? scheduling : polling) += thread_cpu_seconds() - busy;
      if (exhausted && pending == 0) break;
      std::this_thread::sleep_for(backoff.next());
    }
    for (std::thread& t : pool) t.join();
    stats_.scheduler_seconds += scheduling;
    stats_.polling_seconds += polling;
  }

 private:
  MpiJob& job_;
  int threads_;
  ExecutorStats stats_;
};

}  // namespace

MpiJob::MpiJob(int* argc, char*** argv) {
  current_job = this;
  const bool launched =
      std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMIX_RANK") || std::getenv("PMI_RANK");
  if (!launched) return;
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  initialized_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiJob::~MpiJob() {
  if (initialized_) {
    if (rank_ == 0)
      for (int r = 1; r < size_; ++r) MPI_Send(nullptr, 0, MPI_BYTE, r, kTagStop, MPI_COMM_WORLD);
    MPI_Finalize();
  }
  current_job = nullptr;
}

std::unique_ptr<BatchExecutor> MpiJob::executor(int threads) {
  return std::make_unique<MpiExecutor>(*this, threads);
}

int MpiJob::serve() {
  std::unique_ptr<Study> study;
  std::unique_ptr<DesignEvaluator> evaluator;
  std::string unusable;  // why the study sent could not be loaded (then every design fails)
  std::deque<std::pair<long, Design> > work;
  std::vector<std::vector<char> > results;
  std::mutex mutex;
  std::condition_variable work_ready, result_ready;
  bool quit = false;
  std::vector<std::thread> pool;
  auto evaluate_work = [&] {
    std::unique_lock<std::mutex> lock(mutex);
    while (true) {
      work_ready.wait(lock, [&] { return quit || !work.empty(); });
      if (work.empty()) return;
      const auto [index, x] = std::move(work.front());
      work.pop_front();
      lock.unlock();
      DesignOutcome o;
      if (evaluator) {
        o = evaluate_design(*evaluator, x);
      } else {
        o.status = Status::kFailed;
        o.message = "rank " + std::to_string(rank_) + " could not load the study: " + unusable;
      }
      std::vector<char> bytes = pack_result(index, o);
      lock.lock();
      results.push_back(std::move(bytes));
      result_ready.notify_one();
    }
  };

  Backoff backoff(std::chrono::microseconds(1000));
  while (true) {
    std::vector<std::vector<char> > outgoing;
    {
      std::unique_lock<std::mutex> lock(mutex);
      outgoing.swap(results);
    }
    for (const std::vector<char>& bytes : outgoing) send(bytes, 0, kTagResult);
    int found = 0;
    MPI_Status probed;
    MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &found, &probed);
    if (found) {
      backoff.reset();
      const std::vector<char> bytes = receive(probed);
      if (probed.MPI_TAG == kTagStop) break;
      Unpacker u(bytes);
      if (probed.MPI_TAG == kTagStudy) {
        const int threads = u.get<int32_t>();
        const std::string file = u.get_string(), directory = u.get_string();
        Diagnostics diag;
        std::optional<Study> loaded;
        try {
          loaded = load_study(Json::parse(u.get_string()), file, directory, diag);
        } catch (const std::exception& e) {
          unusable = e.what();
        }
        if (loaded && loaded->design) {
          study = std::make_unique<Study>(std::move(*loaded));
          evaluator = std::make_unique<DesignEvaluator>(*study);
        } else if (unusable.empty()) {
          unusable = diag.items().empty()
                         ? "no design study"
                         : diag.items()[0].pointer + ": " + diag.items()[0].message;
        }
        for (int t = 0; t < std::max(1, threads); ++t) pool.emplace_back(evaluate_work);
      } else if (probed.MPI_TAG == kTagWork) {
        const long index = static_cast<long>(u.get<int64_t>());
        Design x = u.get_doubles();
        const std::lock_guard<std::mutex> lock(mutex);
        work.emplace_back(index, std::move(x));
        work_ready.notify_one();
      }
      continue;
    }
    std::unique_lock<std::mutex> lock(mutex);
    result_ready.wait_for(lock, backoff.next(), [&] { return !results.empty(); });
  }
  {
    const std::lock_guard<std::mutex> lock(mutex);
    quit = true;
    work_ready.notify_all();
  }
  for (std::thread& t : pool) t.join();
  return 0;
}

#endif

}  // namespace beamrail
