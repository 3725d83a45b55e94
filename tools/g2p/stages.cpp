// The stage commands: g2p project MODEL, then g2p refine, complete,
// properties and export on its folder (or on a model file with its ground
// truth, --truth). Each is the library's pipeline run from a first to a last
// stage (Pipeline::run_file, Pipeline::resume), written through
// write_pipeline_output like `g2p run`: a folder advanced command by command
// holds what one `g2p run` with the same flags holds.
#include <array>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "commands.h"
#include "common.h"
#include "g2p/folder.h"
#include "g2p/pipeline.h"
#include "stage_flags.h"

namespace g2p::cli {
namespace {

// One stage command: where it starts and stops, and its flags.
struct StageCommand {
  std::string name;              // "refine"
  Stage first = Stage::kRefine;  // where it resumes a folder (project: from the model)
  Stage last = Stage::kRefine;   // where it stops
  std::string source, out;       // SOURCE (folder or model file), -o
  std::string truth, key;        // a model file's ground truth (--truth, --key)
  bool overwrite = false, intermediates = false;
  std::vector<std::string> mesh_formats{"obj"};  // completed/ (g2p complete --format)
  PipelineArgs pipeline;
};

int fail(const StageCommand& c, const Status& s, bool setup = false) {
  // Flags: a bad value, and in setting up the pipeline an unknown backend name.
  const bool usage = s.code() == StatusCode::kInvalidArgument || (setup && s.code() == StatusCode::kNotFound);
  if (usage && report_overrides_error(c.name, c.pipeline.overrides, s)) return kExitUsage;
  std::cerr << "g2p " << c.name << ": error: " << (usage ? s.message() : s.to_string()) << "\n";
  return usage ? kExitUsage : kExitFailure;
}

void print_result(const StageCommand& c, const PipelineResult& r, const std::string& out) {
  for (const std::string& w : r.warnings) std::cerr << "g2p " << c.name << ": warning: " << w << "\n";
  for (const std::string& n : r.overrides_applied) std::cout << "correction: " << n << "\n";
  std::cout << pipeline_summary_text(r);
  if (r.last_stage < Stage::kProject)
    std::printf("g2p %s: %zu views -> %s\n", c.name.c_str(), r.views.size(), out.c_str());
  else
    std::printf("g2p %s: %zu parts -> %s\n", c.name.c_str(), r.projection.parts.size(), out.c_str());
}

int run_stage_command(const StageCommand& c) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const bool folder = fs::is_directory(c.source, ec);
  if (c.first != Stage::kRender && !folder && c.truth.empty())
    return fail(c, Status::InvalidArgument(c.source + " is not a folder; for a model file give its ground truth with "
                                                      "--truth"));
  if (folder && !c.truth.empty())
    return fail(c, Status::InvalidArgument("--truth is for model files; " + c.source + " is a folder"));
  const ImportArgs& import = c.pipeline.import;
  const ImportArgs as_made;
  if (folder && c.first != Stage::kRender &&
      (import.unit != as_made.unit || import.height != as_made.height || import.longest_side != as_made.longest_side ||
       import.up != as_made.up || import.keep_axes || import.no_textures || import.lenient))
    return fail(c, Status::InvalidArgument("the import flags (--unit, --height, --longest-side, --up, --keep-axes, "
                                           "--no-textures, --lenient) are for a model file; " +
                                           c.source +
                                           " keeps the ones it was made with (run g2p project again "
                                           "to change them)"));
  if (folder && c.first != Stage::kRender)  // not a g2p folder, or an older one: said before anything else
    if (Result<FolderManifest> m = read_folder_manifest(c.source); !m.ok()) return fail(c, m.status());
  // A folder is advanced in place unless -o names another; a new folder needs -o.
  const std::string out = !c.out.empty() ? c.out : folder && c.first != Stage::kRender ? c.source : "";
  if (out.empty()) return fail(c, Status::InvalidArgument("give -o OUT for a model file"));
  OutputOptions output;
  output.written_by = "g2p " + c.name;
  output.mesh_formats = c.mesh_formats;
  output.intermediates = c.intermediates;
  std::error_code same_error;
  const bool in_place = folder && fs::exists(out, ec) && fs::equivalent(out, c.source, same_error);
  output.overwrite = c.overwrite || in_place;
  output.input_path = folder ? "" : c.source;
  if (Status s = check_output_folder(out, output); !s.ok())
    return fail(c, Status::InvalidArgument("-o " + s.message() + (c.overwrite ? "" : " (--overwrite replaces it)")));

  Result<Pipeline> pipeline = make_pipeline(c.pipeline);
  if (!pipeline.ok()) return fail(c, pipeline.status(), /*setup=*/true);
  Result<PipelineResult> result = Status::Internal("not run");
  if (c.first == Stage::kRender) {  // g2p project: from the model file
    pipeline->options().last_stage = c.last;
    result = pipeline->run_file(c.source);
  } else if (folder) {
    result = pipeline->resume(c.source, c.first, c.last);
  } else {
    Result<PipelineResult> labelled =
        labelled_from_truth(c.source, c.truth, c.key, pipeline->material_table(), pipeline->options().import);
    if (!labelled.ok()) return fail(c, labelled.status());
    result = pipeline->resume(std::move(*labelled), Stage::kComplete, c.last);
  }
  if (!result.ok()) return fail(c, result.status());
  if (Status s = write_pipeline_output(out, *result, pipeline->options(), output); !s.ok()) return fail(c, s);
  print_result(c, *result, out);
  if (!c.truth.empty() && result->last_stage >= Stage::kProperties) {
    const std::string key = c.key.empty() ? fs::path(c.source).stem().string() : c.key;
    Result<std::array<double, 2>> range = truth_mass_range(c.truth, key);
    const double m = result->properties.object.mass_kg;
    if (range.ok())
      std::printf("plausible mass %.4g - %.4g kg (%s): %s\n", (*range)[0], (*range)[1], c.truth.c_str(),
                  m >= (*range)[0] && m <= (*range)[1] ? "inside" : "OUTSIDE");
  }
  for (const CompletedPart& p : result->completion.parts)
    if (!p.ok) {
      std::cerr << "g2p " << c.name << ": part " << p.part << " failed its checks (see completed/completion.json)\n";
      return kExitFailure;
    }
  return kExitOk;
}

// SOURCE, -o, --overwrite and, for a model file, --truth and --key.
void add_source_flags(CLI::App* cmd, StageCommand& c) {
  cmd->add_option("source", c.source,
                  "Output folder of an earlier stage command or g2p run, or a model file together with --truth")
      ->required();
  cmd->add_option("-o,--output", c.out,
                  "Output folder (default: SOURCE itself, advanced in place; written whole and renamed into place)");
  cmd->add_flag("--overwrite", c.overwrite, "Replace an existing -o folder (only once the new one is complete)");
  cmd->add_option("--truth", c.truth, "For a model file: labels.json with its ground-truth material classes");
  cmd->add_option("--key", c.key, "Entry of --truth to use (default: the model file's stem)");
  cmd->add_option("--materials", c.pipeline.materials,
                  "For a model file: material table JSON (default: the paper's 12 classes; a folder keeps its own)");
  add_overrides_flag(cmd, c.pipeline.overrides);
  add_import_flags(cmd, c.pipeline.import);
}

CLI::App* add_stage(CLI::App& app, Command& run, const std::string& name, const std::string& help, Stage first,
                    Stage last, std::shared_ptr<StageCommand>& c) {
  c = std::make_shared<StageCommand>();
  c->name = name;
  c->first = first;
  c->last = last;
  CLI::App* cmd = app.add_subcommand(name, help);
  std::shared_ptr<StageCommand> captured = c;
  cmd->callback([captured, &run] { run = [captured] { return run_stage_command(*captured); }; });
  return cmd;
}

// MODEL, -o and --overwrite of the commands that start from a model file.
void add_model_flags(CLI::App* cmd, StageCommand& c) {
  cmd->add_option("model", c.source, "Model file")->required();
  cmd->add_option("-o,--output", c.out, "Output folder (must not exist unless --overwrite)")->required();
  cmd->add_flag("--overwrite", c.overwrite, "Replace an existing output folder (only once the new one is complete)");
}

}  // namespace

void add_segment_command(CLI::App& app, Command& run) {
  std::shared_ptr<StageCommand> c;
  CLI::App* cmd = add_stage(app, run, "segment",
                            "Render a model and label every pixel with a material class: the views/ and segmented/ "
                            "of a g2p run folder",
                            Stage::kRender, Stage::kSegment, c);
  add_model_flags(cmd, *c);
  cmd->add_flag("--save-intermediates", c->intermediates,
                "Also every view's buffers and the segmenter's class probabilities (segmented/view_XX_probs.npy)");
  add_labelling_flags(cmd, c->pipeline, /*votes=*/false);
}

void add_project_command(CLI::App& app, Command& run) {
  std::shared_ptr<StageCommand> c;
  CLI::App* cmd = add_stage(app, run, "project",
                            "Render, identify, segment and vote the labels onto the mesh's faces; parts (with "
                            "--refiner, refine them too)",
                            Stage::kRender, Stage::kProject, c);
  PipelineArgs& p = c->pipeline;
  add_model_flags(cmd, *c);
  add_labelling_flags(cmd, p);
  add_refiner_flags(cmd, p.refiner, "none");
  cmd->callback([c, &run] {
    c->last = c->pipeline.refiner.name == "none" ? Stage::kProject : Stage::kRefine;
    run = [c] { return run_stage_command(*c); };
  });
}

void add_refine_command(CLI::App& app, Command& run) {
  std::shared_ptr<StageCommand> c;
  CLI::App* cmd = add_stage(app, run, "refine", "Refine the face labels of a g2p project or g2p run folder (stage 4)",
                            Stage::kRefine, Stage::kRefine, c);
  add_source_flags(cmd, *c);
  add_refiner_flags(cmd, c->pipeline.refiner, "smooth");
}

void add_complete_command(CLI::App& app, Command& run) {
  std::shared_ptr<StageCommand> c;
  CLI::App* cmd = add_stage(app, run, "complete", "Close every part into a watertight volume (stage 5)",
                            Stage::kComplete, Stage::kComplete, c);
  add_source_flags(cmd, *c);
  add_completer_flags(cmd, c->pipeline.completer);
  cmd->add_option("--format", c->mesh_formats, "Formats of the closed parts in completed/: obj, ply, stl")
      ->delimiter(',')
      ->check(CLI::IsMember({"obj", "ply", "stl"}));
}

void add_properties_command(CLI::App& app, Command& run) {
  std::shared_ptr<StageCommand> c;
  CLI::App* cmd = add_stage(app, run, "properties",
                            "Close every part and estimate density, structure and mass properties (stages 5 and 6)",
                            Stage::kComplete, Stage::kProperties, c);
  add_source_flags(cmd, *c);
  add_completer_flags(cmd, c->pipeline.completer);
  add_estimator_flags(cmd, c->pipeline.estimator);
}

void add_export_command(CLI::App& app, Command& run) {
  std::shared_ptr<StageCommand> c;
  CLI::App* cmd = add_stage(app, run, "export",
                            "Collision hulls and the simulation assets: MJCF, URDF, SDF, glTF (stages 5 and 6 first "
                            "when the folder lacks them)",
                            Stage::kDecompose, Stage::kExport, c);
  add_source_flags(cmd, *c);
  add_export_flags(cmd, c->pipeline.export_args);
  add_completer_flags(cmd, c->pipeline.completer);
  add_estimator_flags(cmd, c->pipeline.estimator);
  add_decomposer_flags(cmd, c->pipeline.decomposer);
  add_validate_command(app, run);
}

}  // namespace g2p::cli
