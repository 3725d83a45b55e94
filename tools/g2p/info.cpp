// g2p info FILE: what libg2p reads from a model file.
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "common.h"
#include "g2p/io.h"
#include "json_out.h"

namespace g2p::cli {
namespace {

struct InfoArgs {
  std::string path;
  ImportArgs import;
  bool json = false;
};

const char* alpha_name(AlphaMode m) {
  return m == AlphaMode::kMask ? "MASK" : m == AlphaMode::kBlend ? "BLEND" : "OPAQUE";
}

std::string texture_desc(const Texture& t) {
  if (t.uri.empty()) return "-";
  if (!t.image) return t.uri + " (not loaded)";
  return std::to_string(t.image->width()) + "x" + std::to_string(t.image->height());
}

nlohmann::json vec_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json to_json(const Model& model, const std::vector<int>& faces_per_material) {
  const Eigen::AlignedBox3d box = bounds(model.mesh);
  nlohmann::json materials = nlohmann::json::array();
  for (std::size_t i = 0; i < model.materials.size(); ++i) {
    const SourceMaterial& m = model.materials[i];
    materials.push_back({{"index", i},
                         {"name", m.name},
                         {"faces", faces_per_material[i]},
                         {"base_color", {m.base_color[0], m.base_color[1], m.base_color[2], m.base_color[3]}},
                         {"metallic", m.metallic},
                         {"roughness", m.roughness},
                         {"alpha_mode", alpha_name(m.alpha_mode)},
                         {"transmission", m.transmission},
                         {"base_color_texture", texture_desc(m.base_color_texture)},
                         {"metallic_roughness_texture", texture_desc(m.metallic_roughness_texture)}});
  }
  return {{"path", model.info.path},
          {"format", model.info.format},
          {"unit_scale_m", model.info.unit_scale_m},
          {"up_axis", std::string(1, model.info.up_axis)},
          {"source_meshes", model.info.num_source_meshes},
          {"primitives", model.primitives.size()},
          {"vertices", model.mesh.num_vertices()},
          {"faces", model.mesh.num_faces()},
          {"degenerate_faces", model.info.num_degenerate_faces},
          {"has_uvs", model.mesh.has_uvs()},
          {"bounds_m", {{"min", vec_json(box.min())}, {"max", vec_json(box.max())}}},
          {"surface_area_m2", surface_area(model.mesh)},
          {"materials", materials},
          {"warnings", model.info.warnings}};
}

void print_text(const Model& model, const std::vector<int>& faces_per_material) {
  const Eigen::AlignedBox3d box = bounds(model.mesh);
  const Eigen::Vector3d size = box.sizes();
  std::cout << std::setprecision(4);
  std::cout << model.info.path << " (" << model.info.format << ")\n"
            << "  frame:      " << model.info.unit_scale_m << " m per file unit, up axis " << model.info.up_axis
            << (model.info.file_to_model.topLeftCorner<3, 3>().isDiagonal() ? "" : " -> +Z") << "\n"
            << "  meshes:     " << model.info.num_source_meshes << " source meshes, " << model.primitives.size()
            << " placed in the scene\n"
            << "  faces:      " << model.mesh.num_faces() << " triangles (" << model.info.num_degenerate_faces
            << " degenerate), " << model.mesh.num_vertices() << " vertices, UVs "
            << (model.mesh.has_uvs() ? "yes" : "no") << "\n"
            << "  bounds (m): min (" << box.min().transpose() << ")  max (" << box.max().transpose() << ")  size ("
            << size.transpose() << ")\n"
            << "  area:       " << surface_area(model.mesh) << " m^2\n"
            << "  materials:  " << model.materials.size() << "\n";
  for (std::size_t i = 0; i < model.materials.size(); ++i) {
    const SourceMaterial& m = model.materials[i];
    std::cout << "    [" << i << "] '" << m.name << "'  faces " << faces_per_material[i] << "  base ("
              << m.base_color.transpose() << ")  metallic " << m.metallic << "  roughness " << m.roughness << "  "
              << alpha_name(m.alpha_mode);
    if (m.transmission > 0.f) std::cout << "  transmission " << m.transmission;
    std::cout << "  textures: base " << texture_desc(m.base_color_texture) << ", metallic-roughness "
              << texture_desc(m.metallic_roughness_texture) << "\n";
  }
  for (const std::string& w : model.info.warnings) std::cout << "  warning: " << w << "\n";
}

int run_info(const InfoArgs& args) {
  int exit_code = kExitOk;
  Result<Model> model = load_with_flags("info", args.path, args.import, exit_code);
  if (!model.ok()) return exit_code;
  std::vector<int> faces_per_material(model->materials.size(), 0);
  for (const FaceSource& s : model->mesh.face_source)
    if (s.material >= 0 && s.material < static_cast<int>(faces_per_material.size())) ++faces_per_material[s.material];
  if (args.json)
    std::cout << json_out(to_json(*model, faces_per_material)) << "\n";
  else
    print_text(*model, faces_per_material);
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
