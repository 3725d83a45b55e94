// g2p info FILE: what libg2p reads from a model file.
#include <iostream>
#include <memory>

#include "commands.h"
#include "common.h"
#include "g2p/io.h"

namespace g2p::cli {
namespace {

struct InfoArgs {
  std::string path;
  ImportArgs import;
  bool json = false;
};

int run_info(const InfoArgs& args) {
  int exit_code = kExitOk;
  Result<Model> model = load_with_flags("info", args.path, args.import, exit_code);
  if (!model.ok()) return exit_code;
  std::cout << (args.json ? model_summary_json(*model) + "\n" : model_summary_text(*model));
  return kExitOk;
}

}  // namespace

void add_info_command(CLI::App& app, Command& run) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* cmd = app.add_subcommand("info", "Print the meshes, faces, materials and bounds libg2p reads from a model");
  cmd->add_option("model", args->path, "Model file (glTF/GLB, OBJ, PLY, STL, FBX, DAE, 3MF, ...)")->required();
  add_import_flags(cmd, args->import);
  cmd->add_flag("--json", args->json, "Print a JSON summary instead of text");
  cmd->callback([args, &run] { run = [args] { return run_info(*args); }; });
}

}  // namespace g2p::cli
