// g2p project MODEL -o DIR: render, segment and lift the labels onto the
// mesh; faces.csv, a labelled PLY, parts.json and the labels seen per view.
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "common.h"
#include "g2p/project.h"
#include "g2p/refine.h"
#include "json_out.h"
#include "stage_outputs.h"

namespace g2p::cli {
namespace {

struct ProjectArgs {
  std::string path, out;
  ImportArgs import;
  ViewArgs views;
  SegmenterArgs segmenter;
  std::string materials;
  bool anonymize = false;
  bool soft = false, weight_angle = false, weight_footprint = false;
  double min_part_area = 0.001;
  RefineArgs refine;
  double weld = 1e-6;
};

int fail(const Status& s, const char* what = "") {
  std::cerr << "g2p project: error: " << what << s.to_string() << "\n";
  return kExitFailure;
}

int run_project(const ProjectArgs& args) {
  int exit_code = kExitOk;
  Result<Model> model = load_with_flags("project", args.path, args.import, exit_code);
  if (!model.ok()) return exit_code;
  if (args.anonymize) anonymize_names(*model);
  Result<MaterialTable> table = load_table_flag("project", args.materials, exit_code);
  if (!table.ok()) return exit_code;
  Result<std::unique_ptr<Segmenter>> segmenter = make_segmenter_flag("project", args.segmenter, exit_code);
  if (!segmenter.ok()) return exit_code;
  Result<std::vector<View>> views = render_with_flags("project", *model, args.views, exit_code);
  if (!views.ok()) return exit_code;
  if (Status s = (*segmenter)->set_model(*model, *table); !s.ok()) return fail(s);
  std::vector<LabelMap> maps(views->size());
  for (std::size_t i = 0; i < views->size(); ++i)
    if (Status s = (*segmenter)->segment_into((*views)[i], maps[i]); !s.ok()) return fail(s, "segment: ");

  ProjectOptions options;
  options.vote.mode = args.soft ? VoteMode::kSoft : VoteMode::kHard;
  options.vote.weight_by_angle = args.weight_angle;
  options.vote.weight_by_footprint = args.weight_footprint;
  options.partition.min_part_area_fraction = args.min_part_area;
  options.weld_tolerance = args.weld;
  Result<Projection> projection = project(model->mesh, *views, maps, table->size(), options);
  if (!projection.ok()) return fail(projection.status());

  // Stage 4 (optional): refine the labels, then re-partition with the refined labels.
  nlohmann::json refine_report;
  const std::vector<std::uint8_t> image_decided = (*segmenter)->image_decided_faces();
  if (int code = refine_projection("project", args.refine, *model, *views, *table, options.partition, *projection,
                                   refine_report, &image_decided);
      code != kExitOk)
    return code;

  // What `g2p refine DIR` needs to rebuild this projection.
  const nlohmann::json manifest = {
      {"format", "g2p-project"},
      {"version", 1},
      {"model", std::filesystem::absolute(args.path).string()},
      {"import",
       {{"unit", args.import.unit},
        {"up", args.import.up},
        {"keep_axes", args.import.keep_axes},
        {"no_textures", args.import.no_textures}}},
      {"materials", args.materials.empty() ? "" : std::filesystem::absolute(args.materials).string()},
      {"anonymize_names", args.anonymize},
      {"views", views->size()},
      {"vote", args.soft ? "soft" : "hard"},
      {"weight_angle", args.weight_angle},
      {"weight_footprint", args.weight_footprint},
      {"weld", args.weld},
      {"min_part_area", args.min_part_area}};
  Status s = write_views(args.out, *views);
  if (s.ok()) s = write_label_maps(args.out + "/segmented", maps, *table);
  if (s.ok()) s = write_projection(args.out, *model, *views, *projection, *table, refine_report);
  if (s.ok()) s = write_text_file(args.out + "/project.json", json_out(manifest) + "\n");
  if (!s.ok()) return fail(s);
  int seen = 0;
  for (std::uint8_t v : projection->labels.seen) seen += v;
  std::cout << "projected " << views->size() << " views onto " << model->mesh.num_faces() << " faces (" << seen
            << " seen, " << model->mesh.num_faces() - seen << " filled): " << projection->parts.size() << " parts -> "
            << args.out << "\n";
  print_parts(*projection, *table);
  return kExitOk;
}

}  // namespace

void add_project_command(CLI::App& app, Command& run) {
  auto args = std::make_shared<ProjectArgs>();
  CLI::App* cmd = app.add_subcommand("project", "Render, segment and vote the labels onto the mesh's faces; parts");
  cmd->add_option("model", args->path, "Model file")->required();
  cmd->add_option("-o,--output", args->out, "Output folder (created if needed)")->required();
  cmd->add_option("--materials", args->materials, "Material table JSON (default: the paper's 12 classes)");
  cmd->add_flag("--anonymize-names", args->anonymize, "Replace every name by a meaningless one first");
  cmd->add_flag("--soft", args->soft, "Soft votes: add the segmenter's class probabilities instead of one vote");
  cmd->add_flag("--weight-angle", args->weight_angle, "Weight votes by how squarely the face is seen");
  cmd->add_flag("--weight-footprint", args->weight_footprint, "Weight votes by the surface area a pixel covers");
  cmd->add_option("--min-part-area", args->min_part_area,
                  "Merge parts below this fraction of the total area into a neighbour (default 0.001)")
      ->check(CLI::Range(0.0, 0.5));
  cmd->add_option("--weld", args->weld, "Weld tolerance relative to the object's size (default 1e-6)")
      ->check(CLI::Range(0.0, 0.1));
  add_refiner_flags(cmd, args->refine, "none");
  add_import_flags(cmd, args->import);
  add_view_flags(cmd, args->views);
  add_segmenter_flags(cmd, args->segmenter);
  cmd->callback([args, &run] { run = [args] { return run_project(*args); }; });
}

}  // namespace g2p::cli
