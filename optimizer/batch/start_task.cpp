#include "optimizer/batch/start_task.hpp"

#include <omp.h>

#include <algorithm>
#include <exception>

#include "optimizer/batch/wire.hpp"

namespace beamrail {
namespace {

enum class Message : int32_t { kRecord = 1, kDerivatives = 2 };

void put_matrix(Packer& p, const Eigen::MatrixXd& m) {
  p.put<int64_t>(m.rows());
  p.put<int64_t>(m.cols());
  p.put_doubles(std::vector<double>(m.data(), m.data() + m.size()));
}

Eigen::MatrixXd get_matrix(Unpacker& u) {
  const auto rows = static_cast<Eigen::Index>(u.get<int64_t>());
  const auto cols = static_cast<Eigen::Index>(u.get<int64_t>());
  const std::vector<double> v = u.get_doubles();
  if (rows < 0 || cols < 0 || static_cast<size_t>(rows * cols) != v.size())
    return Eigen::MatrixXd();
  return Eigen::Map<const Eigen::MatrixXd>(v.data(), rows, cols);
}

// Sends each row and derivative as a message.
class SendingSink : public StartSink {
 public:
  explicit SendingSink(const std::function<void(std::vector<char>)>& send) : send_(send) {}
  void record(const OptimizationRecord& r) override {
    Packer p;
    p.put<int32_t>(static_cast<int32_t>(Message::kRecord));
    p.put<int32_t>(r.start);
    p.put<int32_t>(r.evaluation);
    p.put_doubles(r.x);
    p.put_outcome(r.outcome);
    p.put<double>(r.objective);
    p.put<int32_t>(r.feasible ? 1 : 0);
    const std::lock_guard<std::mutex> lock(mutex_);
    send_(std::move(p.bytes));
  }
  void derivatives(const Design& x, const Eigen::MatrixXd& jacobian) override {
    Packer p;
    p.put<int32_t>(static_cast<int32_t>(Message::kDerivatives));
    p.put_doubles(x);
    put_matrix(p, jacobian);
    const std::lock_guard<std::mutex> lock(mutex_);
    send_(std::move(p.bytes));
  }

 private:
  const std::function<void(std::vector<char>)>& send_;
  std::mutex mutex_;
};

std::vector<char> pack_result(const StartResult& r) {
  Packer p;
  p.put<int32_t>(r.index);
  p.put<int32_t>(static_cast<int32_t>(r.result));
  p.put_string(r.message);
  p.put<int32_t>(r.stopped ? 1 : 0);
  p.put<int32_t>(r.budget_spent ? 1 : 0);
  p.put<int64_t>(r.budget_needed);
  p.put<int32_t>(r.nlopt_evaluations);
  p.put<double>(r.objective_scale);
  p.put<int64_t>(r.designs);
  const EvaluationCost& c = r.cost;
  p.put<int64_t>(c.simulated);
  p.put<int64_t>(c.failures);
  p.put<int64_t>(c.exact_gradients);
  p.put<int64_t>(c.gradient_fallbacks);
  p.put_string(c.fallback_reason);
  p.put<int64_t>(static_cast<int64_t>(c.sensitivity_warnings.size()));
  for (const std::string& w : c.sensitivity_warnings) p.put_string(w);
  return std::move(p.bytes);
}

StartTask unpack_task(Unpacker& u) {
  StartTask task;
  task.index = u.get<int32_t>();
  task.x0 = u.get_doubles();
  task.constraint_scales = u.get_doubles();
  return task;
}

}  // namespace

std::vector<char> pack_start_task(const StartTask& task, const std::vector<KnownDesign>& known) {
  Packer p;
  p.put<int32_t>(task.index);
  p.put_doubles(task.x0);
  p.put_doubles(task.constraint_scales);
  p.put<int64_t>(static_cast<int64_t>(known.size()));
  for (const KnownDesign& k : known) {
    p.put_doubles(k.x);
    p.put_outcome(k.outcome);
    p.put<int32_t>(!k.has_jacobian ? 0 : k.jacobian ? 2 : 1);
    if (k.has_jacobian && k.jacobian) put_matrix(p, *k.jacobian);
  }
  return std::move(p.bytes);
}

std::vector<char> run_start_task(const DesignEvaluator& evaluator, int threads,
                                 const std::vector<char>& bytes,
                                 const std::function<void(std::vector<char>)>& send,
                                 const std::atomic<bool>& cancel) {
  try {
    Unpacker u(bytes);
    const StartTask task = unpack_task(u);
    DesignCache cache;
    const long n = static_cast<long>(u.get<int64_t>());
    for (long i = 0; i < n; ++i) {
      const Design x = u.get_doubles();
      cache.add(x, u.get_outcome());
      const int32_t jacobian = u.get<int32_t>();
      if (jacobian == 1) cache.set_jacobian(x, nullptr);
      if (jacobian == 2)
        cache.set_jacobian(x, std::make_shared<const Eigen::MatrixXd>(get_matrix(u)));
    }
    // A task runs in a thread of its own: the sensitivities' parallel loops get `threads` too.
    omp_set_num_threads(std::max(1, threads));
    const OptimizationProblem problem(evaluator.study());
    SendingSink sink(send);
    return pack_result(run_start(problem, evaluator, task, cache, threads, sink, cancel));
  } catch (const std::exception& e) {
    return failed_start_task(bytes, e.what());
  } catch (...) {
    return failed_start_task(bytes, kUnknownException);
  }
}

std::vector<char> failed_start_task(const std::vector<char>& bytes, const std::string& why) {
  Unpacker u(bytes);
  StartResult r;
  r.index = unpack_task(u).index;
  r.result = NLOPT_FAILURE;
  r.message = why;
  return pack_result(r);
}

void unpack_start_message(const std::vector<char>& message, StartSink& sink) {
  Unpacker u(message);
  const auto kind = static_cast<Message>(u.get<int32_t>());
  if (kind == Message::kRecord) {
    OptimizationRecord r;
    r.start = u.get<int32_t>();
    r.evaluation = u.get<int32_t>();
    r.x = u.get_doubles();
    r.outcome = u.get_outcome();
    r.objective = u.get<double>();
    r.feasible = u.get<int32_t>() != 0;
    sink.record(r);
  } else if (kind == Message::kDerivatives) {
    const Design x = u.get_doubles();
    sink.derivatives(x, get_matrix(u));
  }
}

StartResult unpack_start_result(const std::vector<char>& bytes) {
  Unpacker u(bytes);
  StartResult r;
  r.index = u.get<int32_t>();
  r.result = static_cast<nlopt_result>(u.get<int32_t>());
  r.message = u.get_string();
  r.stopped = u.get<int32_t>() != 0;
  r.budget_spent = u.get<int32_t>() != 0;
  r.budget_needed = static_cast<long>(u.get<int64_t>());
  r.nlopt_evaluations = u.get<int32_t>();
  r.objective_scale = u.get<double>();
  r.designs = static_cast<long>(u.get<int64_t>());
  EvaluationCost& c = r.cost;
  c.simulated = static_cast<long>(u.get<int64_t>());
  c.failures = static_cast<long>(u.get<int64_t>());
  c.exact_gradients = static_cast<long>(u.get<int64_t>());
  c.gradient_fallbacks = static_cast<long>(u.get<int64_t>());
  c.fallback_reason = u.get_string();
  const long warnings = static_cast<long>(u.get<int64_t>());
  for (long i = 0; i < warnings && i < 20; ++i) c.sensitivity_warnings.insert(u.get_string());
  return r;
}

}  // namespace beamrail
