// Reading a labelled object back for the stages after project/refine: from a
// `g2p project` or `g2p refine` output folder (project.json + faces.csv), or
// from a model file with ground-truth labels (labels.json, by material).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "common.h"
#include "g2p/complete.h"
#include "g2p/decompose.h"
#include "g2p/materials.h"
#include "g2p/model.h"
#include "g2p/project.h"
#include "g2p/properties.h"
#include "stage_overrides.h"

namespace g2p::cli {

// SOURCE plus --truth/--key for model files.
struct LabelledSourceArgs {
  std::string source;  // folder or model file
  std::string truth;   // labels.json, for a model file
  std::string key;     // entry in labels.json (default: the file's stem)
  std::string materials;
  bool textures = false;           // decode textures (for outputs that show the model's appearance)
  std::string overrides;           // --overrides FILE, applied after the folder's own overrides.json
  bool folder_overrides = true;    // apply the folder's overrides.json
  bool overrides_carried = false;  // `overrides` is another folder's overrides.json, not --overrides
};
void add_labelled_source_flags(CLI::App* cmd, LabelledSourceArgs& args);

struct LabelledObject {
  Model model;
  MaterialTable table;
  FacesFile faces;
  std::string origin;          // "folder DIR" or "ground truth KEY of FILE"
  std::string kind;            // what the run identified the object as (project.json's "object"); "" = unknown
  AppliedOverrides overrides;  // the folder's overrides.json and --overrides, applied to `faces`
};

// Loads the object and applies its corrections (the folder's overrides.json,
// then --overrides); on failure prints the error and sets exit_code.
Result<LabelledObject> load_labelled_source(const std::string& command, const LabelledSourceArgs& args, int& exit_code);

// --completer, --complete-set and --fallback.
struct CompleterArgs {
  std::string name = "partition";
  std::vector<std::string> settings;
  std::string fallback = "partition";
};
void add_completer_flags(CLI::App* cmd, CompleterArgs& args);

// Runs stage 5 on the object with the flags' backends; on failure prints the
// error and sets exit_code. Prints the result unless `quiet`.
Result<Completion> run_completion(const std::string& command, const CompleterArgs& args, const LabelledObject& object,
                                  int& exit_code);

// --decomposer, --decompose-set, --max-hulls and --hull-vertices: the
// collision geometry (decompose stage).
struct DecomposerArgs {
  std::string name = "voxel-cut";
  std::vector<std::string> settings;
  DecomposeOptions options;
};
void add_decomposer_flags(CLI::App* cmd, DecomposerArgs& args);

// --estimator and --estimate-set.
struct EstimatorArgs {
  std::string name = "table";
  std::vector<std::string> settings;
};
void add_estimator_flags(CLI::App* cmd, EstimatorArgs& args);

// Stage 6 on a completed object, with the object's corrections; on failure
// prints the error and sets exit_code.
Result<PropertiesReport> run_estimation(const std::string& command, const EstimatorArgs& args,
                                        const LabelledObject& object, const Completion& completion, int& exit_code);

// A `g2p properties` output folder: properties.json records the source it
// was made from, so `g2p export` can start from the folder and reuse its
// closed parts (completed/) and properties (report.json) as they are.
Status write_properties_manifest(const std::string& out, const LabelledSourceArgs& source);
bool is_properties_folder(const std::string& dir);
struct PropertiesOutput {
  LabelledObject object;
  Completion completion;
  PropertiesReport report;
};
Result<PropertiesOutput> load_properties_output(const std::string& command, const std::string& dir, int& exit_code);

// KEY=VALUE pairs as BackendSettings.
Result<BackendSettings> parse_settings(const std::vector<std::string>& pairs);

}  // namespace g2p::cli
