// g2p batch INPUTS... -o OUT: many models, each through `g2p run` in its own
// worker process (g2p::run_batch), one subfolder per asset and an index.
#include <limits.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "g2p/batch.h"
#include "g2p/vlm.h"
#include "stage_flags.h"

namespace g2p::cli {
namespace {

struct BatchArgs {
  std::vector<std::string> inputs;
  std::string manifest, out, scheduler;
  int jobs = 1;
  double timeout_s = 0.0, memory_limit_gib = 0.0;
  bool retry_failed = false, fail_on_error = false, quiet = false;
  PipelineArgs pipeline;  // every asset's options: `g2p run`'s flags
  std::string options_file;
  std::vector<CLI::Option*> pipeline_flags;  // what --options replaces
};

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_stop(int signal) { g_stop = signal; }

// The running g2p executable, which every asset's worker runs.
std::string own_executable() {
  char path[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", path, sizeof path - 1);
  if (n <= 0) return "";
  path[n] = '\0';
  return path;
}

std::string duration(double s) {
  char buffer[32];
  if (s < 60)
    std::snprintf(buffer, sizeof buffer, "%.0fs", s);
  else if (s < 3600)
    std::snprintf(buffer, sizeof buffer, "%dm%02ds", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  else
    std::snprintf(buffer, sizeof buffer, "%dh%02dm", static_cast<int>(s) / 3600, static_cast<int>(s) / 60 % 60);
  return buffer;
}

// A redrawn bar on a terminal; one line per finished asset otherwise.
class BatchProgressPrinter {
 public:
  explicit BatchProgressPrinter(bool quiet) : quiet_(quiet), tty_(::isatty(STDERR_FILENO) == 1) {}
  void operator()(const BatchProgress& p) {
    if (quiet_) return;
    const std::string eta = p.eta_s < 0 ? std::string("-") : duration(p.eta_s);
    if (tty_) {
      const int width = 24;
      const int filled = p.total == 0 ? width : static_cast<int>(width * p.done / p.total);
      if (!p.last.empty() && p.last.find(": ok") == std::string::npos) {  // a failure stays on screen
        std::fprintf(stderr, "\r\033[K%s\n", p.last.c_str());
      }
      std::fprintf(stderr, "\r\033[K[%-*s] %zu/%zu done, %zu failed, %zu skipped, %zu running, ETA %s", width,
                   std::string(filled, '#').c_str(), p.done, p.total, p.failed, p.skipped, p.running, eta.c_str());
      std::fflush(stderr);
      drawn_ = true;
    } else if (!p.last.empty()) {
      std::fprintf(stderr, "g2p batch: [%zu/%zu, %zu failed, ETA %s] %s\n", p.done, p.total, p.failed, eta.c_str(),
                   p.last.c_str());
    }
  }
  void end_line() {
    if (drawn_) std::fputc('\n', stderr);
    drawn_ = false;
  }

 private:
  bool quiet_, tty_, drawn_ = false;
};

int usage(const std::string& message) {
  std::cerr << "g2p batch: " << message << "\n";
  return kExitUsage;
}

#ifndef G2P_CLI_PYTHON_DIR
#define G2P_CLI_PYTHON_DIR ""
#endif
#ifndef G2P_CLI_INSTALLED_PYTHON_DIR
#define G2P_CLI_INSTALLED_PYTHON_DIR ""
#endif

// `g2p batch --scheduler ADDRESS`: the same batch through the Python module's
// Dask executor (g2p.batch(..., client=Client(ADDRESS))): this process
// becomes bindings/python/g2p_dask_batch.py, which reports as this one does.
int run_on_dask(const BatchArgs& args, const RunOptions& options) {
  const nlohmann::json a = {{"scheduler", args.scheduler},
                            {"shown", redact_url(args.scheduler)},
                            {"inputs", args.inputs},
                            {"manifest", args.manifest},
                            {"output", args.out},
                            {"options", options_file_json(options)},
                            {"timeout", args.timeout_s},
                            {"memory_limit", args.memory_limit_gib},
                            {"connect_timeout", 30},
                            {"retry_failed", args.retry_failed},
                            {"fail_on_error", args.fail_on_error},
                            {"quiet", args.quiet}};
  const std::string j = a.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  // The module of this build first, then the installed one.
  std::string dir;
  for (const char* candidate : {G2P_CLI_PYTHON_DIR, G2P_CLI_INSTALLED_PYTHON_DIR}) {
    if (*candidate != '\0' && ::access((std::string(candidate) + "/g2p_dask_batch.py").c_str(), R_OK) == 0) {
      dir = candidate;
      break;
    }
  }
  if (dir.empty())
    return usage("--scheduler needs libg2p's Python module (build it with pybind11-dev, or install python3-g2p)");
  const std::string driver = dir + "/g2p_dask_batch.py";
  std::string path = dir;
  if (const char* old = std::getenv("PYTHONPATH"); old != nullptr && *old != '\0') path += std::string(":") + old;
  ::setenv("PYTHONPATH", path.c_str(), 1);
  const char* python = std::getenv("G2P_PYTHON");
  if (python == nullptr || *python == '\0')
    python = ::access("/usr/bin/python3", X_OK) == 0 ? "/usr/bin/python3" : "python3";
  std::vector<const char*> argv{python, driver.c_str(), j.c_str(), nullptr};
  std::fflush(nullptr);
  ::execvp(python, const_cast<char* const*>(argv.data()));
  std::cerr << "g2p batch: --scheduler needs Python 3 (" << python << ": " << std::strerror(errno) << ")\n";
  return kExitUsage;
}

int run_batch_command(const BatchArgs& args) {
  if (args.inputs.empty() && args.manifest.empty()) return usage("give model files, folders, patterns or --manifest");
  std::vector<BatchAsset> assets;
  if (!args.manifest.empty()) {
    Result<std::vector<BatchAsset>> listed = read_batch_manifest(args.manifest);
    if (!listed.ok()) {
      std::cerr << "g2p batch: error: " << listed.status().message() << "\n";
      return listed.status().code() == StatusCode::kNotFound ? kExitUsage : kExitFailure;
    }
    assets = std::move(*listed);
  }
  if (!args.inputs.empty()) {
    Result<std::vector<BatchAsset>> listed = list_batch_inputs(args.inputs);
    if (!listed.ok()) return usage(listed.status().message());
    assets.insert(assets.end(), listed->begin(), listed->end());
  }
  if (assets.empty()) {
    std::cerr << "g2p batch: error: no model files found in the inputs\n";
    return kExitFailure;
  }
  if (args.jobs != 1 && !args.scheduler.empty())
    return usage("--jobs and --scheduler exclude each other (the cluster's workers set how many run at a time)");
  if (Status s = name_batch_assets(assets); !s.ok()) {
    std::cerr << "g2p batch: error: " << s.message() << "\n";
    return kExitFailure;
  }

  BatchOptions o;
  o.tool = own_executable();
  o.output_dir = args.out;
  o.jobs = args.jobs;
  o.timeout_s = args.timeout_s;
  o.memory_limit_gib = args.memory_limit_gib;
  o.retry_failed = args.retry_failed;
  Result<RunOptions> options = run_options(args.pipeline, args.options_file, args.pipeline_flags);
  if (!options.ok()) return usage(options.status().message());
  o.run = std::move(*options);
  if (!args.scheduler.empty()) return run_on_dask(args, o.run);
  BatchProgressPrinter printer(args.quiet);
  o.on_progress = [&printer](const BatchProgress& p) { printer(p); };
  o.stop_requested = [] { return static_cast<int>(g_stop); };

  auto previous_int = std::signal(SIGINT, on_stop);
  auto previous_term = std::signal(SIGTERM, on_stop);
  Result<BatchResult> result = run_batch(assets, o);
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  printer.end_line();
  if (!result.ok()) {
    const Status& s = result.status();
    if (s.code() == StatusCode::kInvalidArgument) return usage(s.message());
    std::cerr << "g2p batch: error: " << s.message() << "\n";
    return kExitFailure;
  }
  const BatchResult& r = *result;
  std::size_t ok = 0, failed = 0;  // this run's and the unchanged ones the index keeps
  for (const BatchRow& row : r.rows) {
    if (row.status == "ok") ++ok;
    if (row.status != "failed") continue;
    ++failed;
    const bool listed_by_path = row.origin == row.input;
    std::cerr << "g2p batch: failed: " << row.name << (listed_by_path ? "" : " (" + row.origin + ")") << ": "
              << row.error << "\n";
  }
  std::printf("%zu assets: %zu ok, %zu failed, %zu skipped (unchanged)%s -> %s/index.csv\n", r.rows.size(), r.succeeded,
              r.failed, r.skipped, r.cancelled > 0 ? (", " + std::to_string(r.cancelled) + " cancelled").c_str() : "",
              args.out.c_str());
  if (r.stop_signal != 0) {
    std::cerr << "g2p batch: stopped (" << (r.stop_signal == SIGTERM ? "SIGTERM" : "SIGINT")
              << "); finished assets and the index are kept, a rerun goes on from here\n";
    return r.stop_signal == SIGTERM ? kExitTerminated : kExitCancelled;
  }
  if (ok == 0) return kExitFailure;
  if (args.fail_on_error && failed > 0) return kExitFailure;
  return kExitOk;
}

}  // namespace

void add_batch_command(CLI::App& app, Command& run) {
  auto args = std::make_shared<BatchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "batch", "Many models through `g2p run`, each in its own process: a subfolder per asset and an index, resumable");
  cmd->add_option("inputs", args->inputs, "Model files, folders (every model file below) or quoted patterns ('*.glb')");
  cmd->add_option("--manifest", args->manifest,
                  "CSV (header: path,name,unit,up,segmenter,height,longest_side) or JSON Lines, one model a row");
  cmd->add_option("-o,--output", args->out, "Output folder: a subfolder per asset, index.json, index.csv")->required();
  cmd->add_option("-j,--jobs", args->jobs, "Worker processes at a time (default 1)")->check(CLI::PositiveNumber);
  cmd->add_option("--timeout", args->timeout_s, "Wall-clock limit per asset, seconds (default 0: none)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--memory-limit", args->memory_limit_gib, "Memory limit per asset, GiB (default 0: none)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--scheduler", args->scheduler,
                  "Run on a Dask cluster (tcp://HOST:8786) instead of local workers; needs python3-distributed and "
                  "the g2p Python module, and the same paths on every machine");
  cmd->add_flag("--retry-failed", args->retry_failed, "Also rerun the assets the index records as failed");
  cmd->add_flag("--fail-on-error", args->fail_on_error, "Exit 1 when any asset failed");
  cmd->add_flag("-q,--quiet", args->quiet, "No progress on stderr");
  add_options_file_flag(cmd, args->options_file);
  args->pipeline_flags = add_pipeline_flags(cmd, args->pipeline);
  add_settings_flag(cmd);
  cmd->footer(
      "Each asset runs as `g2p run MODEL -o OUT/NAME` in its own process, with the options `g2p run` takes "
      "(a manifest's columns over them); a crash, timeout or out-of-memory is "
      "recorded in OUT/index.csv and the batch goes on. A rerun skips unchanged assets. Exit codes: 0 done (some "
      "assets may have failed: see the index), 1 nothing succeeded or --fail-on-error with a failure, 2 bad command "
      "line, 130 stopped (Ctrl-C), 143 stopped (SIGTERM); finished assets and the index stay.");
  cmd->callback([args, &run] { run = [args] { return run_batch_command(*args); }; });
}

}  // namespace g2p::cli
