// g2p project MODEL -o DIR: render, segment and lift the labels onto the
// mesh; faces.csv, a labelled PLY, parts.json and the labels seen per view.
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "common.h"
#include "g2p/project.h"
#include "g2p/refine.h"

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
  std::string refiner = "none";
  std::vector<std::string> refiner_settings;
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
  nlohmann::json refine_report = {{"refiner", args.refiner}};
  if (args.refiner != "none") {
    BackendSettings settings;
    for (const std::string& kv : args.refiner_settings) {
      const std::size_t eq = kv.find('=');
      if (eq == std::string::npos || eq == 0) {
        std::cerr << "g2p project: --refine-set expects KEY=VALUE, got '" << kv << "'\n";
        return kExitUsage;
      }
      settings[kv.substr(0, eq)] = kv.substr(eq + 1);
    }
    Result<std::unique_ptr<Refiner>> refiner = make_refiner(args.refiner, settings);
    if (!refiner.ok()) {
      std::cerr << "g2p project: " << refiner.status().message() << "\n";
      return kExitUsage;
    }
    RefineInput in{&model->mesh, &projection->graph, &projection->votes, &projection->labels, &*views, &*table};
    Result<RefineResult> refined = (*refiner)->refine(in);
    if (!refined.ok()) {
      // An optional stage: its failure loses nothing, the projected labels stand.
      std::cerr << "g2p project: warning: refine failed, keeping the projected labels: " << refined.status().to_string()
                << "\n";
      refine_report["error"] = refined.status().to_string();
    } else {
      const std::vector<float> voted_confidence = projection->labels.confidence;
      projection->labels.label = refined->labels;
      projection->parts = partition(model->mesh, projection->graph, projection->labels.label, projection->face_part,
                                    options.partition, &voted_confidence);
      for (int f = 0; f < model->mesh.num_faces(); ++f) {
        const float* h = projection->votes.of(f);
        const int l = projection->labels.label[static_cast<std::size_t>(f)];
        const float t = projection->votes.total[static_cast<std::size_t>(f)];
        projection->labels.confidence[static_cast<std::size_t>(f)] = h != nullptr && t > 0.f && l >= 0 ? h[l] / t : 0.f;
      }
      refine_report["notes"] = refined->notes;
      refine_report["changed_faces"] = refined->changes.size();
      nlohmann::json changes = nlohmann::json::array();
      for (std::size_t i = 0; i < refined->changes.size() && i < 1000; ++i) {
        const LabelChange& c = refined->changes[i];
        changes.push_back({{"face", c.face}, {"from", c.from}, {"to", c.to}, {"reason", c.reason}});
      }
      refine_report["changes_first_1000"] = changes;
      for (const std::string& n : refined->notes) std::cout << n << "\n";
    }
  }

  // The labels seen through every view: what the refine stage (and a person) looks at.
  std::vector<LabelMap> projected;
  for (const View& v : *views) projected.push_back(render_face_labels(v, projection->labels.label));
  Status s = write_views(args.out, *views);
  if (s.ok()) s = write_label_maps(args.out + "/segmented", maps, *table);
  if (s.ok()) s = write_label_maps(args.out + "/projected", projected, *table);
  if (s.ok()) s = write_faces_csv(args.out + "/faces.csv", *model, *projection, *table);
  if (s.ok()) s = write_labelled_ply(args.out + "/labelled.ply", model->mesh, projection->labels.label, *table);
  nlohmann::json parts = nlohmann::json::array();
  for (std::size_t i = 0; i < projection->parts.size(); ++i) {
    const Part& p = projection->parts[i];
    parts.push_back({{"part", i},
                     {"label", table->valid_label(p.label) ? (*table)[p.label].name : std::string()},
                     {"faces", p.faces.size()},
                     {"area_m2", p.area_m2}});
  }
  if (s.ok()) {
    std::ofstream report(args.out + "/refine.json");
    report << refine_report.dump(2) << "\n";
    if (!report) s = Status::IoError(args.out + "/refine.json: cannot write");
  }
  if (s.ok()) {
    std::ofstream out(args.out + "/parts.json");
    out << nlohmann::json{{"parts", parts}}.dump(2) << "\n";
    if (!out) s = Status::IoError(args.out + "/parts.json: cannot write");
  }
  if (!s.ok()) return fail(s);
  int seen = 0;
  for (std::uint8_t v : projection->labels.seen) seen += v;
  std::cout << "projected " << views->size() << " views onto " << model->mesh.num_faces() << " faces (" << seen
            << " seen, " << model->mesh.num_faces() - seen << " filled): " << projection->parts.size() << " parts -> "
            << args.out << "\n";
  for (std::size_t i = 0; i < projection->parts.size(); ++i)
    std::cout << "  part " << i << ": " << parts[i]["label"].get<std::string>() << ", " << parts[i]["faces"]
              << " faces, " << parts[i]["area_m2"] << " m^2\n";
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
  cmd->add_option("--refiner", args->refiner,
                  "Refine the labels: none (default), smooth, vlm (needs --refine-set model=NAME url=URL)");
  cmd->add_option("--refine-set", args->refiner_settings,
                  "Refiner setting KEY=VALUE, repeatable (smooth: lambda, island, sweeps; vlm: url, model, "
                  "api_key_env, timeout, retries, prompt_file, max_views)");
  add_import_flags(cmd, args->import);
  add_view_flags(cmd, args->views);
  add_segmenter_flags(cmd, args->segmenter);
  cmd->callback([args, &run] { run = [args] { return run_project(*args); }; });
}

}  // namespace g2p::cli
