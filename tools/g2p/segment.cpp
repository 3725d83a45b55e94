// g2p segment MODEL -o DIR: render the views and label every pixel's material.
#include <iostream>
#include <memory>

#include "commands.h"
#include "common.h"
#include "g2p/render.h"
#include "g2p/segment.h"

namespace g2p::cli {
namespace {

struct SegmentArgs {
  std::string path, out;
  ImportArgs import;
  ViewArgs views;
  SegmenterArgs segmenter;
  std::string materials;  // material table JSON; "" = the paper's 12 classes
  bool anonymize = false;
};

int run_segment(const SegmentArgs& args) {
  int exit_code = kExitOk;
  Result<Model> model = load_with_flags("segment", args.path, args.import, exit_code);
  if (!model.ok()) return exit_code;
  if (args.anonymize) anonymize_names(*model);
  Result<MaterialTable> table = load_table_flag("segment", args.materials, exit_code);
  if (!table.ok()) return exit_code;
  Result<std::unique_ptr<Segmenter>> segmenter = make_segmenter_flag("segment", args.segmenter, exit_code);
  if (!segmenter.ok()) return exit_code;
  Result<std::vector<View>> views = render_with_flags("segment", *model, args.views, exit_code);
  if (!views.ok()) return exit_code;

  if (Status s = (*segmenter)->set_model(*model, *table); !s.ok()) {
    std::cerr << "g2p segment: error: " << s.to_string() << "\n";
    return s.code() == StatusCode::kInvalidArgument ? kExitUsage : kExitFailure;
  }
  for (const std::string& w : (*segmenter)->warnings()) std::cerr << "g2p segment: warning: " << w << "\n";
  std::vector<LabelMap> maps(views->size());
  for (std::size_t i = 0; i < views->size(); ++i) {
    if (Status s = (*segmenter)->segment_into((*views)[i], maps[i]); !s.ok()) {
      std::cerr << "g2p segment: error: view " << i << ": " << s.to_string() << "\n";
      return kExitFailure;
    }
  }
  Status s = write_views(args.out, *views);
  if (s.ok()) s = write_label_maps(args.out, maps, *table);
  if (!s.ok()) return fail("segment", s);
  std::cout << "segmented " << maps.size() << " views with '" << args.segmenter.name << "' into " << table->size()
            << " classes -> " << args.out << "\n";
  return kExitOk;
}

}  // namespace

void add_segment_command(CLI::App& app, Command& run) {
  auto args = std::make_shared<SegmentArgs>();
  CLI::App* cmd = app.add_subcommand("segment", "Render a model and label every pixel with a material class");
  cmd->add_option("model", args->path, "Model file")->required();
  cmd->add_option("-o,--output", args->out, "Output folder (created if needed)")->required();
  cmd->add_option("--materials", args->materials, "Material table JSON (default: the paper's 12 classes)");
  cmd->add_flag("--anonymize-names", args->anonymize,
                "Replace material, mesh and texture names by meaningless ones before segmenting");
  add_import_flags(cmd, args->import);
  add_view_flags(cmd, args->views);
  add_segmenter_flags(cmd, args->segmenter);
  cmd->callback([args, &run] { run = [args] { return run_segment(*args); }; });
}

}  // namespace g2p::cli
