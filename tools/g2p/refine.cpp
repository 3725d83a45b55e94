// g2p refine DIR: stage 4 on the output folder of `g2p project`. The folder's
// project.json names the model and how it was read; the views (cameras.json,
// view_XX_rgb.png, view_XX_faceid.png) and the segmenter's labels
// (segmented/view_XX_labels_index.png) are read back, the votes and labels
// rebuilt exactly as `g2p project` made them (every step is deterministic),
// and the refined results are written to OUT (default DIR/refined).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "common.h"
#include "json_out.h"
#include "stage_outputs.h"
#include "stage_overrides.h"

namespace g2p::cli {
namespace {

struct RefineCommandArgs {
  std::string dir, out, overrides;
  RefineArgs refine;
};

std::string view_file(const std::string& dir, std::size_t i, const char* what) {
  char name[64];
  std::snprintf(name, sizeof(name), "/view_%02zu_%s.png", i, what);
  return dir + name;
}

Result<std::string> read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open (is this a `g2p project` output folder?)");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

int run_refine(const RefineCommandArgs& args) {
  auto fail = [](const Status& s) {
    std::cerr << "g2p refine: error: " << s.to_string() << "\n";
    return kExitFailure;
  };
  Result<std::string> text = read_text(args.dir + "/project.json");
  if (!text.ok()) return fail(text.status());
  const nlohmann::json manifest = nlohmann::json::parse(*text, nullptr, false);
  if (manifest.is_discarded() || manifest.value("format", "") != "g2p-project")
    return fail(Status::ParseError(args.dir + "/project.json: not a g2p-project manifest"));

  int exit_code = kExitOk;
  ImportArgs import;
  const nlohmann::json imp = manifest.value("import", nlohmann::json::object());
  import.unit = imp.value("unit", "");
  import.up = imp.value("up", "auto");
  import.keep_axes = imp.value("keep_axes", false);
  import.no_textures = imp.value("no_textures", false);
  Result<Model> model = load_with_flags("refine", manifest.value("model", ""), import, exit_code);
  if (!model.ok()) return exit_code;
  if (manifest.value("anonymize_names", false)) anonymize_names(*model);
  if (manifest.value("base_color_only", false)) reduce_to_base_color(*model);
  Result<MaterialTable> table = load_table_flag("refine", manifest.value("materials", ""), exit_code);
  if (!table.ok()) return exit_code;

  // The views and the segmenter's labels, as written by `g2p project` (views
  // at the top of the folder) or `g2p run` (views/).
  const std::string view_dir =
      std::filesystem::exists(args.dir + "/cameras.json") || !std::filesystem::exists(args.dir + "/views/cameras.json")
          ? args.dir
          : args.dir + "/views";
  Result<std::string> cameras_text = read_text(view_dir + "/cameras.json");
  if (!cameras_text.ok()) return fail(cameras_text.status());
  Result<std::vector<Camera>> cameras = cameras_from_json(*cameras_text);
  if (!cameras.ok()) return fail(cameras.status().with_context(view_dir + "/cameras.json"));
  std::vector<View> views(cameras->size());
  std::vector<LabelMap> maps(cameras->size());
  for (std::size_t i = 0; i < cameras->size(); ++i) {
    View& v = views[i];
    v.camera = (*cameras)[i];
    Result<ImageU8> ids = read_image(view_file(view_dir, i, "faceid"));
    Result<ImageI32> face_id = ids.ok() ? decode_face_ids(*ids) : Result<ImageI32>(ids.status());
    Result<ImageU8> rgba = read_image(view_file(view_dir, i, "rgb"));
    Result<ImageU8> index = read_image(view_file(args.dir + "/segmented", i, "labels_index"));
    for (const Status& s : {face_id.status(), rgba.status(), index.status()})
      if (!s.ok()) return fail(s);
    v.face_id = std::move(*face_id);
    v.rgb = ImageU8(rgba->width(), rgba->height(), 3);
    for (int y = 0; y < rgba->height(); ++y)
      for (int x = 0; x < rgba->width(); ++x)
        for (int c = 0; c < 3; ++c) v.rgb.at(x, y, c) = rgba->at(x, y, c);
    maps[i].labels = ImageI32(index->width(), index->height(), 1, kUnknownLabel);
    for (int y = 0; y < index->height(); ++y)
      for (int x = 0; x < index->width(); ++x) {
        const int l = index->at(x, y, 0);
        maps[i].labels.at(x, y) = l == 255 ? kUnknownLabel : l;
      }
    for (int f : v.face_id.storage())
      if (f >= model->mesh.num_faces())
        return fail(Status::InvalidArgument(view_file(view_dir, i, "faceid") +
                                            ": face IDs do not belong to the model named in project.json"));
  }
  if (manifest.value("vote", "hard") != "hard")
    std::cerr << "g2p refine: warning: the project used soft votes; the folder keeps label indices only, so the "
                 "votes are rebuilt as hard votes\n";

  ProjectOptions options;
  options.vote.weight_by_angle = manifest.value("weight_angle", false);
  options.weld_tolerance = manifest.value("weld", 1e-6);
  options.partition.min_part_area_fraction = manifest.value("min_part_area", 0.001);
  if (manifest.value("weight_footprint", false))
    std::cerr << "g2p refine: warning: footprint weights need depth buffers the folder does not keep; not used\n";
  Result<Projection> projection = project(model->mesh, views, maps, table->size(), options);
  if (!projection.ok()) return fail(projection.status());

  nlohmann::json report;
  if (int code =
          refine_projection("refine", args.refine, *model, views, *table, options.partition, *projection, report);
      code != kExitOk)
    return code;
  // Corrections: the folder's own (a run made with --overrides), then --overrides.
  AppliedOverrides corrections;
  for (const std::string& f :
       {std::string(std::filesystem::exists(args.dir + "/overrides.json") ? args.dir + "/overrides.json" : ""),
        args.overrides})
    if (!f.empty() && !apply_overrides_file("refine", f, model->mesh, *table, *projection, corrections, exit_code).ok())
      return exit_code;
  if (!corrections.empty()) report["overrides"] = corrections.notes;
  for (const std::string& n : corrections.notes) std::cout << "correction: " << n << "\n";
  const std::string out = args.out.empty() ? args.dir + "/refined" : args.out;
  Status s = write_projection(out, *model, views, *projection, *table, report);
  // The manifest travels along, so later stages can start from this folder.
  nlohmann::json refined_manifest = manifest;
  refined_manifest["refined_from"] = std::filesystem::absolute(args.dir).string();
  refined_manifest["refiner"] = args.refine.name;
  if (s.ok()) s = write_text_file(out + "/project.json", json_out(refined_manifest) + "\n");
  if (s.ok()) s = write_overrides(out, corrections, *table);
  if (!s.ok()) return fail(s);
  std::cout << "refined with '" << args.refine.name << "': " << projection->parts.size() << " parts -> " << out << "\n";
  print_parts(*projection, *table);
  return kExitOk;
}

}  // namespace

void add_refine_command(CLI::App& app, Command& run) {
  auto args = std::make_shared<RefineCommandArgs>();
  CLI::App* cmd = app.add_subcommand("refine", "Refine the face labels of a `g2p project` output folder");
  cmd->add_option("dir", args->dir, "Output folder of g2p project or g2p run")->required();
  cmd->add_option("-o,--output", args->out, "Where to write the refined results (default DIR/refined)");
  add_refiner_flags(cmd, args->refine, "smooth");
  add_overrides_flag(cmd, args->overrides);
  cmd->callback([args, &run] { run = [args] { return run_refine(*args); }; });
}

}  // namespace g2p::cli
