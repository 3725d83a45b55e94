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
#include "stage_inputs.h"
#include "stage_outputs.h"
#if defined(G2P_CLI_WITH_CGAL)
#include "g2p/complete_cgal.h"
#endif

namespace g2p::cli {
namespace {

struct RunArgs {
  std::string model, out, materials, name, overrides;
  ImportArgs import;
  ViewArgs views;
  IdentifyArgs identify;
  SegmenterArgs segmenter;
  RefineArgs refiner;
  CompleterArgs completer;
  EstimatorArgs estimator;
  DecomposerArgs decomposer;
  std::string vlm_url, vlm_model;
  std::vector<std::string> formats{"mjcf", "urdf", "sdf", "glb"};
  bool soft = false;  // soft votes in the project stage
  bool fixed = false, anonymize = false, base_color_only = false, overwrite = false, intermediates = false,
       json = false, quiet = false;
  double memory_limit_gib = 0.0;
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
#if defined(G2P_CLI_WITH_CGAL)
  (void)register_cgal_completers();
#endif
  if (fs::exists(args.out) && fs::is_directory(args.out) && !args.overwrite)
    return usage(args.out + " exists; choose another folder or pass --overwrite (replaced only once the run succeeds)");
  OutputOptions folder;
  folder.overwrite = args.overwrite;
  folder.input_path = args.model;
  if (Status s = check_output_folder(args.out, folder); !s.ok()) return usage("-o " + s.message());

  PipelineOptions o;
  Result<ImportOptions> import = import_options(args.import);
  if (!import.ok()) return usage(import.status().message());
  o.import = *import;
  o.anonymize_names = args.anonymize;
  o.base_color_only = args.base_color_only;
  if (args.soft) o.project.vote.mode = VoteMode::kSoft;
  Result<ViewOptions> views = view_options(args.views);
  if (!views.ok()) return usage(views.status().message());
  o.views = *views;
  o.renderer.name = args.views.renderer;
  struct StageFlags {
    BackendChoice* choice;
    const std::string* name;
    const std::vector<std::string>* settings;
    const char* flag;
  };
  const StageFlags stages[] = {{&o.identifier, &args.identify.name, &args.identify.settings, "--identify-set"},
                               {&o.segmenter, &args.segmenter.name, &args.segmenter.settings, "--set"},
                               {&o.refiner, &args.refiner.name, &args.refiner.settings, "--refine-set"},
                               {&o.completer, &args.completer.name, &args.completer.settings, "--complete-set"},
                               {&o.estimator, &args.estimator.name, &args.estimator.settings, "--estimate-set"},
                               {&o.decomposer, &args.decomposer.name, &args.decomposer.settings, "--decompose-set"}};
  for (const StageFlags& s : stages) {
    Result<BackendSettings> settings = parse_settings(*s.settings);
    if (!settings.ok()) return usage(std::string(s.flag) + ": " + settings.status().message());
    *s.choice = BackendChoice{*s.name, *settings};
  }
  // --vlm-url/--vlm-model go to every stage that asks a vision-language model.
  if (!args.vlm_url.empty() || !args.vlm_model.empty()) {
    bool used = false;
    for (BackendChoice* c : {&o.identifier, &o.refiner, &o.estimator}) {
      if (c->name != "vlm") continue;
      used = true;
      if (!args.vlm_url.empty()) c->settings.emplace("url", args.vlm_url);
      if (!args.vlm_model.empty()) c->settings.emplace("model", args.vlm_model);
    }
    if (!used) return usage("--vlm-url and --vlm-model need --identifier vlm, --refiner vlm or --estimator vlm");
  }
  o.object = args.identify.object;
  Result<SizePolicy> size_policy = parse_size_policy(args.identify.size_from);
  if (!size_policy.ok()) return usage(size_policy.status().message());
  o.size_policy = *size_policy;
  o.kind_confidence = args.identify.kind_confidence;
  o.kind_prior = args.identify.kind_prior;
  o.completion_fallback = args.completer.fallback == "none" ? "" : args.completer.fallback;
  o.decompose = args.decomposer.options;
  if (!(args.memory_limit_gib >= 0)) return usage("--memory-limit must be 0 (the machine's memory) or more GiB");
  o.memory_limit_bytes = static_cast<std::size_t>(args.memory_limit_gib * 1024.0 * 1024.0 * 1024.0);
  if (Status valid = validate(o.decompose); !valid.ok()) return usage(valid.message());
  o.formats = args.formats;
  o.name = args.name;
  o.export_options.free_joint = !args.fixed;

  Pipeline pipeline(o);
  if (!args.materials.empty()) {
    Result<MaterialTable> table = MaterialTable::load(args.materials);
    if (!table.ok()) return usage(table.status().to_string());
    pipeline.set_material_table(std::move(*table));
  }
  if (!args.overrides.empty()) {
    const MaterialTable& table = pipeline.material_table();
    Result<Overrides> overrides = read_overrides(args.overrides, table);
    if (!overrides.ok()) return usage("--overrides " + overrides.status().message() + "; nothing was written");
    pipeline.options().overrides = std::move(*overrides);
  }
  if (Status s = pipeline.prepare(); !s.ok()) {
    if (s.code() == StatusCode::kInvalidArgument || s.code() == StatusCode::kNotFound) return usage(s.message());
    std::cerr << "g2p run: error: " << s.to_string() << "\n";
    return kExitFailure;
  }

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
    // A file that does not fit the run (a missing part, a failed "was" check)
    // is the user's input, like a bad flag.
    const std::string& m = written.message();
    std::size_t at = m.find(": overrides entry ");
    if (at == std::string::npos) at = m.find(": overrides: ");
    if (!args.overrides.empty() && written.code() == StatusCode::kInvalidArgument && at != std::string::npos) {
      std::cerr << "g2p run: --overrides " << args.overrides << ": " << m.substr(at + 2) << "; nothing was written\n";
      return kExitUsage;
    }
    std::cerr << "g2p run: error: " << written.to_string() << "\n";
    return kExitFailure;
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
  const Identification& id = r.identification;
  if (id.known())
    std::printf("  object: %s (%s, %.0f %% confident)%s\n", id.kind().c_str(), id.source().c_str(),
                100.0 * id.confidence(),
                r.kind.name.empty()    ? ", below --kind-confidence: nothing assumed from it"
                : r.size_assumed_m > 0 ? ", its typical size assumed"
                                       : "");
  else
    std::printf("  object: unknown (give it with --object)\n");
  for (const StageReport& s : r.stages)
    std::printf("  %-10s %-10s %6.2f s %7.0f MiB%s\n", to_string(s.stage), s.backend.c_str(), s.seconds,
                static_cast<double>(s.peak_rss_bytes) / 1048576.0, s.ok ? "" : "  FAILED (skipped)");
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
  cmd->add_option("--materials", args->materials, "Material table JSON (default: the paper's 12 classes)");
  cmd->add_option("--overrides", args->overrides,
                  "Corrections to apply (JSON from summary.html's 3D view, docs/pipeline.md#overrides): classes, "
                  "solid/hollow, wall thickness, density, contents per part or face");
  cmd->add_option("--name", args->name, "Asset name (default: the model file's stem)");
  cmd->add_option("--format", args->formats, "Formats: mjcf, urdf, sdf, glb (comma-separated; default all)")
      ->delimiter(',')
      ->check(CLI::IsMember({"mjcf", "urdf", "sdf", "glb"}));
  cmd->add_flag("--fixed", args->fixed, "MJCF: fix the body to the world instead of a free joint");
  cmd->add_flag("--anonymize-names", args->anonymize, "Replace every name by a meaningless one first");
  cmd->add_flag("--base-color-only", args->base_color_only,
                "Keep only base colour: metallic and roughness at glTF's default of 1, no metallic-roughness texture "
                "or transmission (what image-to-3D generators emit; for measuring)");
  cmd->add_flag("--soft", args->soft,
                "Soft votes: each pixel adds the segmenter's class probabilities instead of one vote (better with "
                "the learned and onnx segmenters)");
  cmd->add_option("--vlm-url", args->vlm_url, "OpenAI-compatible endpoint for the vlm refiner/estimator");
  cmd->add_option("--vlm-model", args->vlm_model, "Model name for the vlm refiner/estimator");
  cmd->add_flag("--overwrite", args->overwrite, "Replace an existing output folder (after the run succeeded)");
  cmd->add_flag("--save-intermediates", args->intermediates,
                "Also write every view's buffers, per-view probabilities, per-face votes and part patches");
  cmd->add_flag("--json", args->json, "Print the run's summary (run.json) on stdout instead of text");
  cmd->add_flag("-q,--quiet", args->quiet, "No progress on stderr");
  cmd->add_option("--memory-limit", args->memory_limit_gib,
                  "Refuse a run whose views and mesh would need more memory, in GiB (default 0: the machine's)");
  add_import_flags(cmd, args->import);
  add_view_flags(cmd, args->views);
  add_identify_flags(cmd, args->identify);
  add_segmenter_flags(cmd, args->segmenter);
  add_refiner_flags(cmd, args->refiner, "smooth");
  add_completer_flags(cmd, args->completer);
  add_estimator_flags(cmd, args->estimator);
  add_decomposer_flags(cmd, args->decomposer);
  cmd->footer(
      "Exit codes: 0 success, 1 the run failed (bad input file, a stage error), 2 bad command line, 130 cancelled "
      "(Ctrl-C), 143 terminated (SIGTERM). Nothing is written unless the run succeeds.");
  cmd->callback([args, &run] { run = [args] { return run_pipeline(*args); }; });
}

}  // namespace g2p::cli
