#include "stage_flags.h"

#include <cstdio>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "g2p/overrides.h"
#if defined(G2P_CLI_WITH_CGAL)
#include "g2p/complete_cgal.h"
#endif

namespace g2p::cli {

void register_optional_backends() {
#if defined(G2P_CLI_WITH_CGAL)
  (void)register_cgal_completers();
#endif
}

const char* settings_flag(Stage stage) {
  switch (stage) {
    case Stage::kIdentify: return "--identify-set";
    case Stage::kSegment: return "--set";
    case Stage::kRefine: return "--refine-set";
    case Stage::kComplete: return "--complete-set";
    case Stage::kProperties: return "--estimate-set";
    case Stage::kDecompose: return "--decompose-set";
    default: return "";
  }
}

Status print_backend_settings(const std::string& name) {
  register_optional_backends();
  Result<std::vector<BackendSettingsInfo>> found = describe_backend_settings(name);
  if (!found.ok()) return found.status();
  for (const BackendSettingsInfo& b : *found) {
    std::printf("%s %s", to_string(b.stage), b.backend.c_str());
    if (b.settings.empty()) {
      std::printf(": no settings\n");
      continue;
    }
    std::printf(" (%s KEY=VALUE):\n", settings_flag(b.stage));
    for (const SettingInfo& i : b.settings) {
      std::printf("  %-26s %s (default %s): %s\n", i.key.c_str(), i.takes().c_str(),
                  i.value.empty() ? "\"\"" : i.value.c_str(), i.help.c_str());
    }
  }
  return Status::Ok();
}

void add_settings_flag(CLI::App* cmd) {
  cmd->add_option_function<std::string>(
         "--settings",
         [](const std::string& name) {
           if (Status s = print_backend_settings(name); !s.ok()) throw CLI::ValidationError("--settings", s.message());
           throw CLI::Success();
         },
         "List a backend's settings with their types, ranges and defaults, and exit: NAME (every stage's backend "
         "of that name), STAGE:NAME (refine:vlm) or all")
      ->trigger_on_parse();
}

void add_refiner_flags(CLI::App* cmd, RefineArgs& args, const std::string& default_name) {
  args.name = default_name;
  cmd->add_option("--refiner", args.name,
                  "Refiner: " + backend_list(refiner_registry().names()) + " (vlm needs --refine-set model=NAME)")
      ->capture_default_str();
  cmd->add_option("--refine-set", args.settings,
                  "Refiner setting KEY=VALUE, repeatable (`g2p run --settings refine:NAME` lists them)");
}

void add_completer_flags(CLI::App* cmd, CompleterArgs& args) {
  register_optional_backends();
  cmd->add_option("--completer", args.name, "Completer: " + backend_list(completer_registry().names()))
      ->capture_default_str();
  cmd->add_option("--complete-set", args.settings,
                  "Completer setting KEY=VALUE, repeatable (`g2p run --settings complete:NAME` lists them)");
  cmd->add_option("--fallback", args.fallback, "Completer for the parts the completer fails, or 'none'")
      ->capture_default_str();
}

void add_estimator_flags(CLI::App* cmd, EstimatorArgs& args) {
  cmd->add_option("--estimator", args.name, "Property estimator: " + backend_list(estimator_registry().names()))
      ->capture_default_str();
  cmd->add_option("--estimate-set", args.settings,
                  "Estimator setting KEY=VALUE, repeatable (`g2p run --settings properties:NAME` lists them)");
}

void add_decomposer_flags(CLI::App* cmd, DecomposerArgs& args) {
  cmd->add_option("--decomposer", args.name,
                  "Collision geometry: " + backend_list(decomposer_registry().names()) +
                      " (voxel-cut: a convex decomposition; hull: one convex hull per part)")
      ->capture_default_str();
  cmd->add_option("--decompose-set", args.settings,
                  "Decomposer setting KEY=VALUE, repeatable (`g2p run --settings decompose:NAME` lists them)");
  cmd->add_option("--max-hulls", args.options.max_hulls,
                  "Convex hulls per part at most (1-256), unless --coverage-tolerance raises it")
      ->capture_default_str();
  cmd->add_option("--hull-vertices", args.options.max_vertices_per_hull,
                  "Vertices per convex hull at most (4-255; engines cap hulls at 255)")
      ->capture_default_str();
  cmd->add_option("--min-concavity", args.options.min_depth_m,
                  "Leave concavities shallower than this alone, in metres (0: 1 % of the object's bounding-box "
                  "diagonal)")
      ->capture_default_str();
  cmd->add_option("--coverage-tolerance", args.options.coverage_tolerance,
                  "Hulls should stand no farther outside a part, nor leave its surface uncovered by more, than this "
                  "share of the object's bounding-box diagonal (0-1); a part that spends its hull budget and misses "
                  "it gets twice the budget")
      ->capture_default_str();
  cmd->add_option("--max-hulls-per-object", args.options.max_hulls_per_object,
                  "Convex hulls per object at most when raising part budgets for --coverage-tolerance (0: never "
                  "raise)")
      ->capture_default_str();
}

void add_export_flags(CLI::App* cmd, ExportArgs& args) {
  cmd->add_option("--name", args.name, "Asset name (default: the model file's stem)");
  cmd->add_option("--format", args.formats, "Formats: mjcf, urdf, sdf, glb (comma-separated; default all)")
      ->delimiter(',')
      ->check(CLI::IsMember({"mjcf", "urdf", "sdf", "glb"}));
  cmd->add_flag("--fixed", args.fixed, "MJCF: fix the body to the world instead of a free joint");
}

void add_overrides_flag(CLI::App* cmd, std::string& path) {
  cmd->add_option("--overrides", path,
                  "Corrections to apply (JSON from summary.html's 3D view, docs/pipeline.md#overrides): classes, "
                  "solid/hollow, wall thickness, density, contents per part or face");
}

bool report_overrides_error(const std::string& command, const std::string& overrides, const Status& s) {
  const std::string& m = s.message();
  std::size_t at = m.find(": overrides entry ");
  if (at == std::string::npos) at = m.find(": overrides: ");
  if (overrides.empty() || s.code() != StatusCode::kInvalidArgument || at == std::string::npos) return false;
  std::cerr << "g2p " << command << ": --overrides " << overrides << ": " << m.substr(at + 2)
            << "; nothing was written\n";
  return true;
}

Result<BackendSettings> parse_settings(const std::vector<std::string>& pairs) {
  BackendSettings s;
  for (const std::string& p : pairs) {
    const std::size_t eq = p.find('=');
    if (eq == std::string::npos || eq == 0) return Status::InvalidArgument("expected KEY=VALUE, got '" + p + "'");
    s[p.substr(0, eq)] = p.substr(eq + 1);
  }
  return s;
}

Result<PipelineOptions> pipeline_options(const PipelineArgs& args) {
  PipelineOptions o;
  Result<ImportOptions> import = import_options(args.import);
  if (!import.ok()) return import.status();
  o.import = *import;
  o.anonymize_names = args.anonymize;
  o.base_color_only = args.base_color_only;
  if (args.soft) o.project.vote.mode = VoteMode::kSoft;
  Result<ViewOptions> views = view_options(args.views);
  if (!views.ok()) return views.status();
  o.views = *views;
  o.renderer.name = args.views.renderer;
  struct StageFlags {
    BackendChoice* choice;
    const std::string* name;
    const std::vector<std::string>* settings;
    Stage stage;
  };
  const StageFlags stages[] = {{&o.identifier, &args.identify.name, &args.identify.settings, Stage::kIdentify},
                               {&o.segmenter, &args.segmenter.name, &args.segmenter.settings, Stage::kSegment},
                               {&o.refiner, &args.refiner.name, &args.refiner.settings, Stage::kRefine},
                               {&o.completer, &args.completer.name, &args.completer.settings, Stage::kComplete},
                               {&o.estimator, &args.estimator.name, &args.estimator.settings, Stage::kProperties},
                               {&o.decomposer, &args.decomposer.name, &args.decomposer.settings, Stage::kDecompose}};
  for (const StageFlags& s : stages) {
    Result<BackendSettings> settings = parse_settings(*s.settings);
    if (!settings.ok()) return settings.status().with_context(settings_flag(s.stage));
    *s.choice = BackendChoice{*s.name, *settings};
  }
  if (args.refiner.name == "none" && !args.refiner.settings.empty())
    return Status::InvalidArgument("--refine-set needs a --refiner other than none");
  // --vlm-url/--vlm-model go to every stage that asks a vision-language model.
  if (!args.vlm_url.empty() || !args.vlm_model.empty()) {
    bool used = false;
    for (BackendChoice* c : {&o.identifier, &o.refiner, &o.estimator}) {
      if (c->name != "vlm") continue;
      used = true;
      if (!args.vlm_url.empty()) c->settings.emplace("url", args.vlm_url);
      if (!args.vlm_model.empty()) c->settings.emplace("model", args.vlm_model);
    }
    if (!used)
      return Status::InvalidArgument(
          "--vlm-url and --vlm-model need --identifier vlm, --refiner vlm or --estimator vlm");
  }
  o.object = args.identify.object;
  Result<SizePolicy> size_policy = parse_size_policy(args.identify.size_from);
  if (!size_policy.ok()) return size_policy.status();
  o.size_policy = *size_policy;
  o.kind_confidence = args.identify.kind_confidence;
  o.kind_prior = args.identify.kind_prior;
  o.kind_posterior = args.identify.kind_mass == "on";
  o.completion_fallback = args.completer.fallback == "none" ? "" : args.completer.fallback;
  o.decompose = args.decomposer.options;
  if (!(args.memory_limit_gib >= 0))
    return Status::InvalidArgument("--memory-limit must be 0 (the machine's memory) or more GiB");
  o.memory_limit_bytes = static_cast<std::size_t>(args.memory_limit_gib * 1024.0 * 1024.0 * 1024.0);
  G2P_RETURN_IF_ERROR(validate(o.decompose));
  o.formats = args.export_args.formats;
  o.name = args.export_args.name;
  o.export_options.free_joint = !args.export_args.fixed;
  return o;
}

void add_labelling_flags(CLI::App* cmd, PipelineArgs& p, bool votes) {
  cmd->add_option("--materials", p.materials, "Material table JSON (default: the paper's 12 classes)");
  cmd->add_flag("--anonymize-names", p.anonymize, "Replace every name by a meaningless one first");
  cmd->add_flag("--base-color-only", p.base_color_only,
                "Keep only base colour: metallic and roughness at glTF's default of 1, no metallic-roughness texture "
                "or transmission (what image-to-3D generators emit; for measuring)");
  if (votes)
    cmd->add_flag("--soft", p.soft,
                  "Soft votes: each pixel adds the segmenter's class probabilities instead of one vote (better with "
                  "the learned and onnx segmenters)");
  add_import_flags(cmd, p.import);
  add_view_flags(cmd, p.views);
  add_identify_flags(cmd, p.identify);
  add_segmenter_flags(cmd, p.segmenter);
}

std::vector<CLI::Option*> add_pipeline_flags(CLI::App* cmd, PipelineArgs& p) {
  const std::size_t before = cmd->get_options().size();
  add_labelling_flags(cmd, p);
  add_export_flags(cmd, p.export_args);
  cmd->add_option("--vlm-url", p.vlm_url, "OpenAI-compatible endpoint for the vlm refiner/estimator");
  cmd->add_option("--vlm-model", p.vlm_model, "Model name for the vlm refiner/estimator");
  add_refiner_flags(cmd, p.refiner, PipelineOptions{}.refiner.name);
  add_completer_flags(cmd, p.completer);
  add_estimator_flags(cmd, p.estimator);
  add_decomposer_flags(cmd, p.decomposer);
  const std::vector<CLI::Option*> all = cmd->get_options();
  return std::vector<CLI::Option*>(all.begin() + static_cast<std::ptrdiff_t>(before), all.end());
}

void add_options_file_flag(CLI::App* cmd, std::string& path) {
  cmd->add_option("--options", path,
                  "Every option from a JSON options file instead of flags: any subset of its keys, the rest at their "
                  "defaults (docs/pipeline.md#options-files; each output folder's options.json is one)");
}

Result<RunOptions> run_options(const PipelineArgs& args, const std::string& options_file,
                               const std::vector<CLI::Option*>& flags) {
  if (options_file.empty()) {
    Result<PipelineOptions> options = pipeline_options(args);
    if (!options.ok()) return options.status();
    RunOptions run{std::move(*options)};
    if (!args.materials.empty()) {
      Result<MaterialTable> table = MaterialTable::load(args.materials);
      if (!table.ok()) return table.status().with_context("--materials");
      run.materials = std::move(*table);
    }
    return run;
  }
  for (const CLI::Option* f : flags)
    if (f->count() > 0)
      return Status::InvalidArgument(f->get_name() + " and --options exclude each other: give it in " + options_file +
                                     " instead");
  Result<RunOptions> run = read_options_file(options_file);
  if (!run.ok()) return run.status().with_context("--options");
  return run;
}

Result<Pipeline> make_pipeline(RunOptions options, const std::string& overrides) {
  register_optional_backends();
  Pipeline pipeline(std::move(options.pipeline));
  pipeline.set_material_table(std::move(options.materials));
  if (!overrides.empty()) {
    Result<Overrides> read = read_overrides(overrides, pipeline.material_table());
    if (!read.ok()) return Status::InvalidArgument("--overrides " + read.status().message());
    pipeline.options().overrides = std::move(*read);
  }
  G2P_RETURN_IF_ERROR(pipeline.prepare());
  return pipeline;
}

Result<Pipeline> make_pipeline(const PipelineArgs& args) {
  Result<RunOptions> options = run_options(args, "", {});
  if (!options.ok()) return options.status();
  return make_pipeline(std::move(*options), args.overrides);
}

}  // namespace g2p::cli
