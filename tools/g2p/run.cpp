// g2p run MODEL -o DIR: the whole method in one call (g2p::Pipeline), from a
// mesh file to the simulation assets, a report and summary.html.
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "common.h"
#include "g2p/pipeline.h"
#include "stage_flags.h"

namespace g2p::cli {
namespace {

struct RunArgs {
  std::string model, out, options_file;
  PipelineArgs pipeline;
  std::vector<CLI::Option*> pipeline_flags;  // what --options replaces
  bool overwrite = false, intermediates = false, json = false, quiet = false;
};

// The run's context, reachable from the SIGINT and SIGTERM handler (cancel()
// is a lock-free atomic store). TERM is what `timeout`, CI runners and
// containers send; both end the run cleanly, with nothing half-written.
RunContext* g_context = nullptr;
volatile std::sig_atomic_t g_signal = 0;
extern "C" void on_interrupt(int signal) {
  g_signal = signal;
  if (g_context != nullptr) g_context->cancel();
}

// Progress on stderr: a redrawn bar on a terminal, one line per stage otherwise.
class ProgressPrinter {
 public:
  explicit ProgressPrinter(bool quiet) : quiet_(quiet), tty_(::isatty(STDERR_FILENO) == 1) {}
  void operator()(const Progress& p) {
    if (quiet_) return;
    if (tty_) {
      const int width = 30, filled = static_cast<int>(p.overall * width + 0.5);
      std::fprintf(stderr, "\r[%-*s] %3d%% %-10s %-28.28s", width, std::string(filled, '#').c_str(),
                   static_cast<int>(p.overall * 100 + 0.5), to_string(p.stage), p.message.c_str());
      if (p.stage == Stage::kExport && p.stage_fraction >= 1.0) std::fputc('\n', stderr);
      std::fflush(stderr);
    } else if (p.stage != last_ || p.stage_fraction >= 1.0) {
      std::fprintf(stderr, "g2p run: %s %s%s\n", to_string(p.stage), p.stage_fraction >= 1.0 ? "done: " : "",
                   p.message.c_str());
    }
    last_ = p.stage;
  }
  void end_line() {
    if (!quiet_ && tty_) std::fputc('\n', stderr);
  }

 private:
  bool quiet_, tty_;
  Stage last_ = Stage::kLoad;
};

int usage(const std::string& message) {
  std::cerr << "g2p run: " << message << "\n";
  return kExitUsage;
}

int run_pipeline(const RunArgs& args) {
  namespace fs = std::filesystem;
  if (fs::exists(args.out) && fs::is_directory(args.out) && !args.overwrite)
    return usage(args.out + " exists; choose another folder or pass --overwrite (replaced only once the run succeeds)");
  OutputOptions folder;
  folder.overwrite = args.overwrite;
  folder.input_path = args.model;
  if (Status s = check_output_folder(args.out, folder); !s.ok()) return usage("-o " + s.message());
  Result<RunOptions> options = run_options(args.pipeline, args.options_file, args.pipeline_flags);
  Result<Pipeline> made =
      options.ok() ? make_pipeline(std::move(*options), args.pipeline.overrides) : Result<Pipeline>(options.status());
  if (!made.ok()) {
    const Status& s = made.status();
    if (s.code() == StatusCode::kInvalidArgument || s.code() == StatusCode::kNotFound ||
        s.code() == StatusCode::kParseError)
      return usage(s.message() + (args.pipeline.overrides.empty() ? "" : "; nothing was written"));
    std::cerr << "g2p run: error: " << s.to_string() << "\n";
    return kExitFailure;
  }
  Pipeline& pipeline = *made;
  const PipelineOptions& o = pipeline.options();

  ProgressPrinter printer(args.quiet);
  RunContext context([&printer](const Progress& p) { printer(p); });
  g_context = &context;
  auto previous = std::signal(SIGINT, on_interrupt);
  auto previous_term = std::signal(SIGTERM, on_interrupt);
  Result<PipelineResult> result = pipeline.run_file(args.model, &context);
  Status written = result.ok() ? Status::Ok() : result.status();
  if (result.ok() && !context.cancelled()) {
    OutputOptions out;
    out.overwrite = args.overwrite;
    out.intermediates = args.intermediates;
    out.written_by = "g2p run";
    written = write_pipeline_output(args.out, *result, o, out);
  }
  std::signal(SIGINT, previous);
  std::signal(SIGTERM, previous_term);
  g_context = nullptr;
  if (context.cancelled() && !(result.ok() && written.ok())) {
    printer.end_line();
    std::cerr << "g2p run: cancelled" << (g_signal == SIGTERM ? " (SIGTERM)" : "") << "; nothing was written\n";
    return g_signal == SIGTERM ? kExitTerminated : kExitCancelled;
  }
  if (context.cancelled())  // the interrupt came while the folder was being written: it is complete
    std::cerr << "g2p run: interrupted after the run; the output is complete\n";
  if (!written.ok()) {
    printer.end_line();
    if (report_overrides_error("run", args.pipeline.overrides, written)) return kExitUsage;
    return fail("run", written);
  }
  const PipelineResult& r = *result;
  for (const std::string& w : r.warnings) std::cerr << "g2p run: warning: " << w << "\n";
  for (const std::string& c : r.overrides_applied) std::cerr << "g2p run: correction: " << c << "\n";
  if (args.json) {
    std::cout << pipeline_summary_json(r, o) << "\n";
    return kExitOk;
  }
  std::printf("%s: %d triangles -> %zu parts, %.4g kg (range %.3g-%.3g kg) in %.2f s -> %s\n", args.model.c_str(),
              r.model.mesh.num_faces(), r.projection.parts.size(), r.properties.object.mass_kg,
              r.properties.mass_min_kg, r.properties.mass_max_kg, r.seconds, args.out.c_str());
  std::cout << pipeline_summary_text(r);
  std::printf("  open %s/summary.html\n", args.out.c_str());
  return kExitOk;
}

}  // namespace

void add_run_command(CLI::App& app, Command& run) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run", "The whole pipeline: render, segment, project, refine, complete, properties and export in one call");
  cmd->add_option("model", args->model, "Model file (glTF/GLB, OBJ, PLY, STL, FBX, ...)")->required();
  cmd->add_option("-o,--output", args->out, "Output folder (must not exist unless --overwrite)")->required();
  PipelineArgs& p = args->pipeline;
  add_overrides_flag(cmd, p.overrides);
  add_options_file_flag(cmd, args->options_file);
  cmd->add_flag("--overwrite", args->overwrite, "Replace an existing output folder (after the run succeeded)");
  cmd->add_flag("--save-intermediates", args->intermediates,
                "Also write every view's buffers, per-view probabilities, per-face votes and part patches");
  cmd->add_flag("--json", args->json, "Print the run's summary (run.json) on stdout instead of text");
  cmd->add_flag("-q,--quiet", args->quiet, "No progress on stderr");
  args->pipeline_flags = add_pipeline_flags(cmd, p);
  args->pipeline_flags.push_back(
      cmd->add_option("--memory-limit", p.memory_limit_gib,
                      "Refuse a run whose views and mesh would need more memory, in GiB (default 0: the machine's)"));
  add_settings_flag(cmd);
  cmd->footer(
      "Exit codes: 0 success, 1 the run failed (bad input file, a stage error), 2 bad command line, 130 cancelled "
      "(Ctrl-C), 143 terminated (SIGTERM). Nothing is written unless the run succeeds.");
  cmd->callback([args, &run] { run = [args] { return run_pipeline(*args); }; });
}

}  // namespace g2p::cli
