#include "optimizer/cli/cli.hpp"

#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <new>

#include "core/analysis/dense_product.hpp"
#include "core/analysis/stop_request.hpp"
#include "core/model/element_kinds.hpp"
#include "optimizer/batch/mpi_job.hpp"
#include "optimizer/batch/run_settings.hpp"
#include "optimizer/cli/batch_commands.hpp"
#include "optimizer/cli/interruption.hpp"
#include "optimizer/output/output_folder.hpp"
#include "optimizer/output/result_tables.hpp"
#include "optimizer/output/summary.hpp"
#include "optimizer/output/tables.hpp"
#include "optimizer/output/version.hpp"
#include "optimizer/output/vtk_design.hpp"
#include "optimizer/output/vtk_output.hpp"
#include "optimizer/run/evaluation.hpp"
#include "optimizer/run/status.hpp"
#include "optimizer/study/study.hpp"

namespace beamrail {
namespace {

constexpr const char* kUsage =
    R"(beamrail - design optimizer for rigid bodies joined by elastic beams and rails

Usage:
  beamrail run STUDY.json [-o OUTDIR] [-j THREADS] [--resume] [--quiet] [--vtk [--design ROW]]
  beamrail check STUDY.json
  beamrail --help | --version

Commands:
  run     validate the study, run its analyses and write the result tables to OUTDIR
          (default: results/<study name>/): summary.json, timeseries.csv, ...
  check   validate the study only; list every problem as file:/json/pointer: message

Options:
  -o, --output OUTDIR   where to write the results
  -j, --threads N       threads for batch evaluation, 1..1024 (default: all cores; never
                        more than the designs evaluated at once); a single run shares the
                        modal method's dense products among them (default: one thread) and
                        runs a transient's verification rerun beside the run on a second
                        (default: when the process may use two cores; -j 1: after the run)
  --resume              continue an interrupted sweep or optimization in OUTDIR (refused
                        when OUTDIR's tables were written by another version of the study)
  --quiet               no progress output
  --vtk                 also write VTK files for ParaView into OUTDIR/vtk (as "outputs":
                        {"vtk": true} does): a .pvd per analysis; for a design study, of the
                        best design (optimize) or of the design chosen with --design
  --design ROW          the design the VTK files draw: a sweep's index (samples.csv), an
                        optimization's EVALUATION of start 1 or START:EVALUATION (history.csv)

Exit status: 0 success; 1 the run failed, or its results could not be written, or OUTDIR is
in use by another run (the reason is printed, partial tables are kept); 2 bad input (unreadable
or invalid study, bad command line, --resume of tables another study wrote); 130 and 143
interrupted by SIGINT and SIGTERM (what was computed is kept).
)";

struct RunArguments {
  std::string study;
  std::string output;
  int threads = 0;
  bool resume = false;
  bool quiet = false;
  bool vtk = false;                   // --vtk
  std::optional<std::string> design;  // --design ROW
};

// The message and the usage lines only: the full help would bury the message.
int usage_error(const std::string& message) {
  std::cerr << "beamrail: " << message << "\n"
            << "usage: beamrail run STUDY.json [-o OUTDIR] [-j THREADS] [--resume] [--quiet] "
               "[--vtk [--design ROW]]\n"
            << "       beamrail check STUDY.json\n"
            << "       beamrail --help | --version\n";
  return 2;
}

// Parses the arguments after "run" or "check"; returns an exit status on error.
std::optional<int> parse_run_arguments(const std::vector<std::string>& args, bool run,
                                       RunArguments& out) {
  for (size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](const char* what) -> std::optional<std::string> {
      if (i + 1 >= args.size()) return std::nullopt;
      (void)what;
      return args[++i];
    };
    if (run && (a == "-o" || a == "--output")) {
      const auto v = value("OUTDIR");
      if (!v || v->empty()) return usage_error(a + " needs a directory");
      out.output = *v;
    } else if (run && (a == "-j" || a == "--threads")) {
      const auto v = value("N");
      try {
        size_t used = 0;
        const long n = v ? std::stol(*v, &used) : -1;
        if (!v || used != v->size() || n < 1) throw std::invalid_argument("");
        if (n > kMaxThreads)
          return usage_error(a + " " + *v + ": at most " + std::to_string(kMaxThreads) +
                             " threads (a batch never uses more threads than designs it can "
                             "evaluate at once)");
        out.threads = static_cast<int>(n);
      } catch (const std::exception&) {
        return usage_error(a + " needs a positive number of threads");
      }
    } else if (run && a == "--resume") {
      out.resume = true;
    } else if (run && a == "--quiet") {
      out.quiet = true;
    } else if (run && a == "--vtk") {
      out.vtk = true;
    } else if (run && a == "--design") {
      const auto v = value("ROW");
      if (!v || v->empty()) return usage_error(a + " needs a design (a row of the batch's table)");
      out.design = *v;
    } else if (!a.empty() && a[0] == '-') {
      return usage_error("unknown option " + a);
    } else if (out.study.empty()) {
      out.study = a;
    } else {
      return usage_error("more than one study file given");
    }
  }
  if (out.study.empty()) return usage_error("no study file given");
  return std::nullopt;
}

int check(const RunArguments& args) {
  Diagnostics diag;
  const auto study = load_study_file(args.study, diag);
  if (!study) {
    std::cerr << diag.format();
    return 2;
  }
  for (const std::string& w : study->input_warnings) std::cerr << "warning: " << w << "\n";
  const Model& m = study->model;
  std::cout << args.study << ": ok (" << m.bodies.size() - 1 << " bodies, ";
  for_each_element_kind([&](auto kind) {
    using Kind = decltype(kind);
    const size_t n = Kind::elements(m).size();
    if (n > 0 || Kind::kCountedWhenNone) std::cout << n << " " << Kind::kName << "s, ";
  });
  std::cout << m.n_states << " states, " << study->analyses.size() << " analyses, "
            << study->responses.size() << " responses)\n";
  for (const SegmentChoice& c : m.segment_choices) {
    char line[200];
    std::snprintf(line, sizeof line,
                  "  beam \"%s\": %ld segments (auto; estimated bending-frequency error %.2g)\n",
                  c.beam.c_str(), c.segments, c.estimated_error);
    std::cout << line;
  }
  return 0;
}

// The command that runs the study again into the same folder.
std::string command_line(const RunArguments& args, const std::filesystem::path& out) {
  // Under mpirun, as many ranks again (a scheduler's launcher may say so in its own way).
  const MpiJob* job = mpi_job();
  std::string c = job && job->size() > 1 ? "mpirun -n " + std::to_string(job->size()) + " " : "";
  c += "beamrail run " + args.study + " -o " + out.string();
  if (args.threads > 0) c += " -j " + std::to_string(args.threads);
  return c;
}

// The table a resumed batch continues ("" when the study cannot resume).
std::string resumable_table(const Study& study) {
  if (!study.design) return "";
  switch (study.design->type) {
    case DesignStudy::Type::kSweep:
      return "samples.csv";
    case DesignStudy::Type::kOptimize:
      return "history.csv";
    case DesignStudy::Type::kWorkPrecision:
    case DesignStudy::Type::kSensitivity:
      break;
  }
  return "";
}

int run_single(const Study& study, const std::filesystem::path& out, bool vtk, bool verify_beside) {
  EvaluationOptions options;
  options.result_tables = true;
  options.verify_beside = verify_beside;
  TimeseriesFiles timeseries(out);
  options.timeseries = &timeseries;
  std::optional<VtkOutput> vtk_output;
  if (vtk) options.vtk = &vtk_output.emplace(out / "vtk");
  Evaluation ev = evaluate(study, study.model, options);
  // The tables of the analyses that ran (those of a failed or interrupted run's earlier analyses
  // too); a write error fails the analysis and, unless it failed already, the run.
  for (AnalysisReport& report : ev.analyses) {
    std::string table_error;
    if (write_result_tables(out, report.result_tables, &table_error)) continue;
    report.ok = false;
    report.message = table_error;
    if (ev.status == Status::kOk) ev.status = Status::kFailed, ev.message = table_error;
    break;
  }
  std::string vtk_error;
  if (vtk_output && !vtk_output->finish(nullptr, &vtk_error) && ev.status == Status::kOk)
    ev.status = Status::kFailed, ev.message = vtk_error;
  const nlohmann::json summary = evaluation_summary(study, study.model, ev);
  std::string error;
  if (!write_file_atomically(out / "summary.json", summary.dump(2) + "\n", &error)) {
    std::cerr << "beamrail: " << error << "\n";
    return 1;
  }
  for (const std::string& w : ev.warnings) std::cerr << "warning: " << w << "\n";
  if (ev.status == Status::kInterrupted) {
    const int signal = stop_requested();
    std::cerr << "beamrail: " << study.name << " interrupted by " << signal_name(signal) << ": "
              << ev.message << "; the tables in " << out.string()
              << " hold what was computed up to then (summary.json says so); run it again to "
                 "compute it all\n";
    return interrupted_exit_status(signal);
  }
  if (ev.status != Status::kOk) {
    std::cerr << "beamrail: " << study.name << " " << status_name(ev.status) << ": " << ev.message
              << "\n(partial results kept in " << out.string() << ")\n";
    return 1;
  }
  std::cout << study.name << ": ok in " << ev.wall_seconds << " s -> " << out.string() << "\n";
  for (size_t k = 0; k < study.responses.size(); ++k)
    std::cout << "  " << study.responses[k].name << " = " << format_number(ev.responses[k]) << "\n";
  return 0;
}

int run(const RunArguments& args) {
  Diagnostics diag;
  const auto study = load_study_file(args.study, diag);
  if (!study) {
    std::cerr << diag.format();
    return 2;
  }
  for (const std::string& w : study->input_warnings) std::cerr << "warning: " << w << "\n";
  // Which design the VTK files draw; a bad --design is refused before the folder is touched.
  const bool vtk = args.vtk || study->vtk;
  DesignChoice drawn;
  if (const std::string refusal =
          choose_design(*study, vtk, args.design ? &*args.design : nullptr, &drawn);
      !refusal.empty()) {
    std::cerr << "beamrail: " << refusal << "\n";
    return 2;
  }
  const std::filesystem::path out = args.output.empty()
                                        ? std::filesystem::path("results") / study->name
                                        : std::filesystem::path(args.output);
  // Held until the run ends: a second run into the same folder is refused.
  OutputFolder folder;
  std::string error, warning;
  if (!folder.acquire(out, &error, &warning)) {
    std::cerr << "beamrail: " << error << "\n";
    return 1;
  }
  if (!warning.empty()) std::cerr << "warning: " << warning << "\n";
  const std::string table = resumable_table(*study);
  if (args.resume && !table.empty()) {
    const std::string refusal = resume_refusal(*study, out, table);
    if (!refusal.empty()) {
      std::cerr << "beamrail: " << refusal << "\n";
      return 2;
    }
  }
  if (!folder.start(*study, &error)) {
    std::cerr << "beamrail: " << error << "\n";
    return 1;
  }

  const StopOnSignals signals;
  // Under mpirun the other ranks evaluate a sweep's designs, run an optimization's starts and a
  // work-precision study's runs, and evaluate a sensitivity check's designs; a single run runs
  // here alone.
  if (const MpiJob* job = mpi_job(); job && job->size() > 1 && !study->design)
    std::cerr << "beamrail: only design studies spread over MPI ranks; this single run runs on "
                 "rank 0 alone (the other "
              << job->size() - 1 << " wait)\n";
  const RunSettings settings{out, args.threads, args.resume, args.quiet, command_line(args, out)};
  // A single run, and a work-precision study's runs one after another, share their dense
  // products (the modal method's) among the threads -j names; without -j, one. A shared product
  // waits for every thread of its team, so beside other work it waits for the busiest core: two
  // runs of the braced tower at once on 2 cores took 25.6 s with 2 threads each against 8.9 s
  // with one (alone, 4.4 s with 2). A batch's designs run one per thread, and MPI ranks one run
  // each.
  const MpiJob* job = mpi_job();
  int product_budget = 1;
  if (!(job && job->size() > 1) &&
      (!study->design || study->design->type == DesignStudy::Type::kWorkPrecision))
    product_budget = std::max(1, args.threads);
  const ProductThreads product_threads(product_budget);
  if (study->design) {
    int status = 0;
    switch (study->design->type) {
      case DesignStudy::Type::kSweep:
        status = run_sweep(*study, settings);
        break;
      case DesignStudy::Type::kOptimize:
        status = run_optimize(*study, settings);
        break;
      case DesignStudy::Type::kWorkPrecision:
        status = run_work_precision(*study, settings);
        break;
      case DesignStudy::Type::kSensitivity:
        status = run_sensitivity(*study, settings);
        break;
    }
    // The VTK files of the design chosen, once the batch has succeeded.
    return status == 0 ? draw_design(*study, drawn, out, args.quiet) : status;
  }
  // A transient's verification rerun runs beside the run on a second core (-j 2 or more, or
  // without -j where the process may use two: omp_get_num_procs follows the CPU affinity, as a
  // batch's threads do; std::thread::hardware_concurrency counts the machine's, and under
  // taskset -c 0 a run beside its rerun on one core timed out where it ran in 1.5 s alone).
  const bool verify_beside = args.threads > 0 ? args.threads >= 2 : omp_get_num_procs() >= 2;
  return run_single(*study, out, vtk, verify_beside);
}

int dispatch(const std::vector<std::string>& args) {
  if (args.empty()) return usage_error("no command given");
  const std::string& command = args[0];
  if (command == "--help" || command == "-h" || command == "help") {
    std::cout << kUsage;
    return 0;
  }
  if (command == "--version") {
    std::cout << "beamrail " << kVersion << "\n";
    return 0;
  }
  if (command != "run" && command != "check") return usage_error("unknown command " + command);
  RunArguments parsed;
  if (const auto status = parse_run_arguments(args, command == "run", parsed)) return *status;
  return command == "run" ? run(parsed) : check(parsed);
}

}  // namespace

int beamrail_main(int argc, char** argv) {
  // Under mpirun (or srun) every rank starts here; rank 0 runs the command line, the others
  // evaluate the designs it sends them (optimizer/batch/mpi_job.hpp).
  MpiJob job(&argc, &argv);
  if (job.rank() > 0) {
    const StopOnSignals signals;
    job.serve();
    return 0;
  }
  return run_command_line(std::vector<std::string>(argv + 1, argv + argc));
}

int run_command_line(const std::vector<std::string>& args) {
  try {
    return dispatch(args);
  } catch (const std::bad_alloc&) {
    std::cerr << "beamrail: out of memory\n";
  } catch (const std::exception& e) {
    std::cerr << "beamrail: internal error: " << e.what() << "\n";
  } catch (...) {
    std::cerr << "beamrail: internal error\n";
  }
  return 1;
}

}  // namespace beamrail
