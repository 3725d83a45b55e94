// Flags and helpers shared by the g2p subcommands.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include <memory>
#include <vector>

#include "g2p/io.h"
#include "g2p/materials.h"
#include "g2p/options_file.h"
#include "g2p/pipeline.h"
#include "g2p/render.h"
#include "g2p/segment.h"

namespace g2p::cli {

// "g2p COMMAND: error: STATUS" on stderr; returns kExitFailure.
int fail(const std::string& command, const Status& status);
// A value the user gave that does not fit (InvalidArgument; NotFound: a file
// or backend the command line names) is "g2p COMMAND: MESSAGE", exit 2;
// anything else as fail().
int fail_or_usage(const std::string& command, const Status& status);

// How a model file is read: --unit, --up, --keep-axes, --no-textures.
struct ImportArgs {
  std::string unit;           // "" = from the format
  double height = 0.0;        // metres; 0 = the file's size
  double longest_side = 0.0;  // metres; 0 = the file's size
  std::string up = "auto";
  bool keep_axes = false;
  bool no_textures = false;
  bool lenient = false;  // keep the good triangles of a damaged file (warnings instead of an error)
};

// A flag's check: a finite number from lo (or above it, when above_lo) to hi.
// CLI11's own range checks let NaN through.
CLI::Validator finite_number(double lo, double hi, bool above_lo = false);

void add_import_flags(CLI::App* cmd, ImportArgs& args);

// The flags as import options (an unknown --unit is an error).
Result<ImportOptions> import_options(const ImportArgs& args);

// Loads `path` with the flags; on failure prints "g2p COMMAND: error: ..." and
// returns the exit code in `exit_code`.
Result<Model> load_with_flags(const std::string& command, const std::string& path, const ImportArgs& args,
                              int& exit_code);

// Which views to render: --views, --resolution, --layout, --fov, --ortho, --renderer.
struct ViewArgs {
  int views = ViewOptions{}.num_views;
  int resolution = ViewOptions{}.width;
  std::string layout = to_string(ViewOptions{}.layout);
  double fov = ViewOptions{}.fov_y_deg;
  bool ortho = ViewOptions{}.orthographic;
  std::string renderer = PipelineOptions{}.renderer.name;
};

void add_view_flags(CLI::App* cmd, ViewArgs& args);
// A stage's backends for a flag's help: "hybrid, pbr, learned".
std::string backend_list(const std::vector<std::string>& names);
Result<ViewOptions> view_options(const ViewArgs& args);

// Renders the model's views with the flags (full shading and buffers).
Result<std::vector<View>> render_with_flags(const std::string& command, const Model& model, const ViewArgs& args,
                                            int& exit_code);

// Which segmenter: --segmenter NAME, --set KEY=VALUE (repeatable).
struct SegmenterArgs {
  std::string name = PipelineOptions{}.segmenter.name;
  std::vector<std::string> settings;
};

void add_segmenter_flags(CLI::App* cmd, SegmenterArgs& args);
Result<std::unique_ptr<Segmenter>> make_segmenter_flag(const std::string& command, const SegmenterArgs& args,
                                                       int& exit_code);

// What the object is, and the size its kind may give it: --object,
// --identifier, --identify-set, --size-from, --kind-confidence.
struct IdentifyArgs {
  std::string object;  // the user's words; "" = none
  std::string name = PipelineOptions{}.identifier.name;
  std::vector<std::string> settings;
  std::string size_from = to_string(PipelineOptions{}.size_policy);
  double kind_confidence = PipelineOptions{}.kind_confidence;
  double kind_prior = PipelineOptions{}.kind_prior;
  std::string kind_mass = PipelineOptions{}.kind_posterior ? "on" : "off";  // --kind-mass
};

void add_identify_flags(CLI::App* cmd, IdentifyArgs& args);

// The material table of --materials ("" = the paper's default).
Result<MaterialTable> load_table_flag(const std::string& command, const std::string& path, int& exit_code);

}  // namespace g2p::cli
