// The flags of the pipeline's stages, one group per stage, and the library
// options they make: g2p run, project, refine, complete, properties, export
// and batch register the groups they take; pipeline_options() turns all of
// them into one PipelineOptions (a group a command does not take keeps the
// library's default, which the flags' defaults are).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "common.h"
#include "g2p/options_file.h"
#include "g2p/pipeline.h"

namespace g2p::cli {

// The GPL component's completers, in a build that has it (idempotent).
void register_optional_backends();

// Every setting of the backends `name` names ("hybrid", "refine:vlm", "all";
// describe_backend_settings), with the flag that sets it, on stdout.
Status print_backend_settings(const std::string& name);
// --settings NAME: print_backend_settings, then exit.
void add_settings_flag(CLI::App* cmd);
// The flag that sets a stage's backend settings ("--refine-set").
const char* settings_flag(Stage stage);

// --refiner, --refine-set.
struct RefineArgs {
  std::string name = PipelineOptions{}.refiner.name;
  std::vector<std::string> settings;
};
void add_refiner_flags(CLI::App* cmd, RefineArgs& args, const std::string& default_name);

// --completer, --complete-set and --fallback.
struct CompleterArgs {
  std::string name = PipelineOptions{}.completer.name;
  std::vector<std::string> settings;
  std::string fallback = PipelineOptions{}.completion_fallback;
};
void add_completer_flags(CLI::App* cmd, CompleterArgs& args);

// --estimator and --estimate-set.
struct EstimatorArgs {
  std::string name = PipelineOptions{}.estimator.name;
  std::vector<std::string> settings;
};
void add_estimator_flags(CLI::App* cmd, EstimatorArgs& args);

// --decomposer, --decompose-set, --max-hulls, --hull-vertices, --min-concavity,
// --coverage-tolerance, --max-hulls-per-object.
struct DecomposerArgs {
  std::string name = PipelineOptions{}.decomposer.name;
  std::vector<std::string> settings;
  DecomposeOptions options;
};
void add_decomposer_flags(CLI::App* cmd, DecomposerArgs& args);

// --name, --format, --fixed.
struct ExportArgs {
  std::string name;
  std::vector<std::string> formats = PipelineOptions{}.formats;
  bool fixed = false;
};
void add_export_flags(CLI::App* cmd, ExportArgs& args);

// --overrides FILE (g2p/overrides.h, docs/pipeline.md#overrides).
void add_overrides_flag(CLI::App* cmd, std::string& path);

// Every stage's flags.
struct PipelineArgs {
  std::string materials, overrides;
  ImportArgs import;
  ViewArgs views;
  IdentifyArgs identify;
  SegmenterArgs segmenter;
  RefineArgs refiner;
  CompleterArgs completer;
  EstimatorArgs estimator;
  DecomposerArgs decomposer;
  ExportArgs export_args;
  std::string vlm_url, vlm_model;
  bool soft = false, anonymize = false, base_color_only = false;
  double memory_limit_gib = 0.0;
};

// The flags of the stages up to the labels: --materials, --anonymize-names,
// --base-color-only, --soft (with `votes`) and the import, view, identify and
// segmenter flags.
void add_labelling_flags(CLI::App* cmd, PipelineArgs& args, bool votes = true);

// Every option flag of `g2p run` but --overrides and --memory-limit (which
// g2p batch has as its own): the flags an options file replaces. Returns them.
std::vector<CLI::Option*> add_pipeline_flags(CLI::App* cmd, PipelineArgs& args);

// --options FILE: the options from a file (g2p/options_file.h) instead of `flags`.
void add_options_file_flag(CLI::App* cmd, std::string& path);
// The options of --options FILE, or of the flags; giving both is an error naming the flag.
Result<RunOptions> run_options(const PipelineArgs& args, const std::string& options_file,
                               const std::vector<CLI::Option*>& flags);

// The options the flags ask for; a bad value fails naming its flag.
Result<PipelineOptions> pipeline_options(const PipelineArgs& args);

// A pipeline with the options and --overrides loaded; prepare()d, so unknown
// backends and settings fail here, before any work.
Result<Pipeline> make_pipeline(RunOptions options, const std::string& overrides);
// The same with the flags' options and --materials.
Result<Pipeline> make_pipeline(const PipelineArgs& args);

// A corrections file that does not fit the run (a missing part, a failed
// "was" check) is the user's input, like a bad flag: prints "g2p COMMAND:
// --overrides FILE: ...; nothing was written" and returns true when `s` (an
// InvalidArgument) says so.
bool report_overrides_error(const std::string& command, const std::string& overrides, const Status& s);

// KEY=VALUE pairs as BackendSettings.
Result<BackendSettings> parse_settings(const std::vector<std::string>& pairs);

}  // namespace g2p::cli
