#include "common.h"

#include <iostream>
#include <map>

#include "commands.h"

namespace g2p::cli {

void add_import_flags(CLI::App* cmd, ImportArgs& args) {
  cmd->add_option("--unit", args.unit,
                  "Unit of the file's coordinates: m, cm, mm, km, in, ft (default: from the format)");
  cmd->add_option("--up", args.up, "Up axis of the file: auto, x, y, z")
      ->transform(CLI::IsMember({"auto", "x", "y", "z"}, CLI::ignore_case));
  cmd->add_flag("--keep-axes", args.keep_axes, "Keep the file's axes (default: rotate its up axis to +Z)");
  cmd->add_flag("--no-textures", args.no_textures, "Do not decode textures");
}

Result<Model> load_with_flags(const std::string& command, const std::string& path, const ImportArgs& args,
                              int& exit_code) {
  ImportOptions options;
  if (!args.unit.empty()) {
    Result<double> scale = parse_unit(args.unit);
    if (!scale.ok()) {
      std::cerr << "g2p " << command << ": " << scale.status().message() << "\n";
      exit_code = kExitUsage;
      return scale.status();
    }
    options.unit_scale = *scale;
  }
  static const std::map<std::string, UpAxis> kAxes = {
      {"auto", UpAxis::kAuto}, {"x", UpAxis::kX}, {"y", UpAxis::kY}, {"z", UpAxis::kZ}};
  const auto axis = kAxes.find(args.up);
  options.up_axis = axis != kAxes.end() ? axis->second : UpAxis::kAuto;
  options.z_up = !args.keep_axes;
  options.load_textures = !args.no_textures;
  Result<Model> model = load_model(path, options);
  if (!model.ok()) {
    std::cerr << "g2p " << command << ": error: " << model.status().to_string() << "\n";
    exit_code = kExitFailure;
  }
  return model;
}

}  // namespace g2p::cli
