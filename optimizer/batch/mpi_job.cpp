#include "optimizer/batch/mpi_job.hpp"

#include <cstdlib>

#include "core/analysis/stop_request.hpp"
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

#include "optimizer/batch/start_task.hpp"
#include "optimizer/batch/wire.hpp"
#include "optimizer/batch/work_precision.hpp"
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
void MpiJob::serve() {}
std::unique_ptr<BatchExecutor> MpiJob::executor(int threads) {
  return std::make_unique<ThreadExecutor>(threads);
}
std::vector<bool> MpiJob::run_tasks(const Study&, int, TaskKind,
                                    const std::vector<std::vector<char>>& tasks,
                                    const TaskCallbacks& callbacks) {
  // A job of one rank: every task here, in order.
  std::vector<bool> ran(tasks.size(), false);
  std::atomic<bool> cancel(false);
  for (size_t i = 0; i < tasks.size() && !cancel && !stop_requested(); ++i) {
    ran[i] = true;
    const std::vector<char> result = callbacks.run_here(
        tasks[i],
        [&](std::vector<char> m) {
          if (!callbacks.message(static_cast<long>(i), m)) cancel = true;
        },
        cancel);
    if (!callbacks.finished(static_cast<long>(i), 0, result)) cancel = true;
  }
  return ran;
}

#else

bool mpi_available() { return true; }

namespace {

// Message tags: rank 0 sends the study, designs, tasks, cancellations and the stop; the others
// send outcomes, the messages of their tasks and the tasks' results.
constexpr int kTagStudy = 1, kTagWork = 2, kTagResult = 3, kTagStop = 4, kTagTask = 5,
              kTagTaskMessage = 6, kTagTaskDone = 7, kTagCancel = 8;

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

// Sends the study to the other ranks, once per job.
void send_study(MpiJob& job, const Study& study, int threads) {
  if (job.study_sent) return;
  Packer p;
  p.put<int32_t>(threads);
  p.put_string(study.file);
  p.put_string(study.directory.string());
  p.put_string(study.document.dump());
  for (int r = 1; r < job.size(); ++r) send(p.bytes, r, kTagStudy);
  job.study_sent = true;
}

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
    send_study(job_, evaluator.study(), threads_);
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
    std::vector<int> ahead(size, 0);
    long pending = 0;  // designs sent and not back yet
    bool exhausted = false;
    // Tops up every other rank's window of designs ahead.
    const auto fill = [&] {
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
    };
    // The other ranks' first designs go out before rank 0's own threads start taking designs: a
    // batch of quick designs is not all done on rank 0 while the others wait for work.
    const double first = thread_cpu_seconds();
    fill();
    scheduling += thread_cpu_seconds() - first;
    std::vector<std::thread> pool;
    for (int t = 0; t < threads_; ++t)
      pool.emplace_back([&] {
        for (long i = take(); i >= 0; i = take())
          deliver(0, i, evaluate_design(evaluator, designs[i]));
      });

    Backoff backoff(std::chrono::microseconds(1000));
    while (true) {
      const double busy = thread_cpu_seconds();
      const long pending_before = pending;
      fill();
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

std::vector<bool> MpiJob::run_tasks(const Study& study, int threads, TaskKind kind,
                                    const std::vector<std::vector<char>>& tasks,
                                    const TaskCallbacks& callbacks) {
  send_study(*this, study, threads);
  const long n = static_cast<long>(tasks.size());
  std::vector<char> ran(tasks.size(), 0);
  std::mutex callback_mutex;  // the callbacks are called one at a time
  std::atomic<bool> stopped(false), cancel(false);
  std::atomic<long> next(0);
  // The next task to start, -1 when none is left or the batch stops.
  auto take = [&]() -> long {
    if (stopped || stop_requested()) return -1;
    const long i = next++;
    return i < n ? i : -1;
  };
  // Rank 0 runs tasks too, one at a time, beside this thread's scheduling.
  std::thread here([&] {
    for (long i = take(); i >= 0; i = take()) {
      ran[i] = 1;
      const std::vector<char> result = callbacks.run_here(
          tasks[i],
          [&](std::vector<char> m) {
            const std::lock_guard<std::mutex> lock(callback_mutex);
            if (!callbacks.message(i, m)) stopped = true, cancel = true;
          },
          cancel);
      const std::lock_guard<std::mutex> lock(callback_mutex);
      if (!callbacks.finished(i, 0, result)) stopped = true, cancel = true;
    }
  });
  std::vector<long> running(size_, -1);  // the task each rank runs
  long pending = 0;                      // tasks sent and not finished
  bool cancel_sent = false;
  Backoff backoff(std::chrono::microseconds(1000));
  while (true) {
    if (!cancel_sent && (stopped || stop_requested())) {
      cancel = true;
      for (int r = 1; r < size_; ++r)
        if (running[r] >= 0) MPI_Send(nullptr, 0, MPI_BYTE, r, kTagCancel, MPI_COMM_WORLD);
      cancel_sent = true;
    }
    for (int r = 1; r < size_ && !cancel_sent; ++r)
      if (running[r] < 0) {
        const long i = take();
        if (i < 0) break;
        ran[i] = 1;
        Packer p;  // the kind, then the task
        p.put<int32_t>(static_cast<int32_t>(kind));
        p.bytes.insert(p.bytes.end(), tasks[i].begin(), tasks[i].end());
        send(p.bytes, r, kTagTask);
        running[r] = i;
        ++pending;
      }
    int found = 0;
    MPI_Status probed;
    MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &found, &probed);
    if (found) {
      const std::vector<char> bytes = receive(probed);
      const int r = probed.MPI_SOURCE;
      if (running[r] >= 0 && probed.MPI_TAG == kTagTaskMessage) {
        const std::lock_guard<std::mutex> lock(callback_mutex);
        if (!callbacks.message(running[r], bytes)) stopped = true;
      } else if (running[r] >= 0 && probed.MPI_TAG == kTagTaskDone) {
        const long i = running[r];
        running[r] = -1;
        --pending;
        const std::lock_guard<std::mutex> lock(callback_mutex);
        if (!callbacks.finished(i, r, bytes)) stopped = true;
      }
      backoff.reset();
      continue;
    }
    if (pending == 0 && (next >= n || cancel_sent)) break;
    std::this_thread::sleep_for(backoff.next());
  }
  here.join();
  return std::vector<bool>(ran.begin(), ran.end());
}

void MpiJob::serve() {
  std::unique_ptr<Study> study;
  std::unique_ptr<DesignEvaluator> evaluator;
  std::string unusable;  // why the study sent could not be loaded (then every design fails)
  std::deque<std::pair<long, Design>> work;
  std::vector<std::pair<int, std::vector<char>>> results;  // tag, message
  std::mutex mutex;
  std::condition_variable work_ready, result_ready;
  bool quit = false;
  std::vector<std::thread> pool;
  int threads = 1;   // per design batch and per task, as rank 0 says
  std::thread task;  // the task (optimization start) under way, one at a time
  std::atomic<bool> cancel(false);
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
      results.emplace_back(kTagResult, std::move(bytes));
      result_ready.notify_one();
    }
  };

  Backoff backoff(std::chrono::microseconds(1000));
  while (true) {
    std::vector<std::pair<int, std::vector<char>>> outgoing;
    {
      std::unique_lock<std::mutex> lock(mutex);
      outgoing.swap(results);
    }
    for (const auto& [tag, bytes] : outgoing) send(bytes, 0, tag);
    int found = 0;
    MPI_Status probed;
    MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &found, &probed);
    if (found) {
      backoff.reset();
      const std::vector<char> bytes = receive(probed);
      if (probed.MPI_TAG == kTagStop) break;
      Unpacker u(bytes);
      if (probed.MPI_TAG == kTagStudy) {
        threads = std::max(1, u.get<int32_t>());
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
        for (int t = 0; t < threads; ++t) pool.emplace_back(evaluate_work);
      } else if (probed.MPI_TAG == kTagTask) {
        if (task.joinable()) task.join();  // rank 0 sends a task once the last one finished
        cancel = false;
        const auto kind = static_cast<TaskKind>(u.get<int32_t>());
        const std::vector<char> body(bytes.begin() + std::min<size_t>(bytes.size(), 4),
                                     bytes.end());
        task = std::thread([&, kind, body] {
          const auto send_message = [&](std::vector<char> m) {
            const std::lock_guard<std::mutex> lock(mutex);
            results.emplace_back(kTagTaskMessage, std::move(m));
            result_ready.notify_one();
          };
          const std::string why =
              "rank " + std::to_string(rank_) + " could not load the study: " + unusable;
          std::vector<char> result;
          if (kind == TaskKind::kPrecisionRun)
            result = run_precision_task(study.get(), body, nullptr);
          else
            result = evaluator ? run_start_task(*evaluator, threads, body, send_message, cancel)
                               : failed_start_task(body, why);
          const std::lock_guard<std::mutex> lock(mutex);
          results.emplace_back(kTagTaskDone, std::move(result));
          result_ready.notify_one();
        });
      } else if (probed.MPI_TAG == kTagCancel) {
        cancel = true;
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
  if (task.joinable()) task.join();
}

#endif

}  // namespace beamrail
