// What libg2p read from a model file, as `g2p info` shows it: text and JSON.
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/json_text.h"
#include "g2p/io.h"

namespace g2p {
namespace {

const char* alpha_name(AlphaMode m) {
  return m == AlphaMode::kMask ? "MASK" : m == AlphaMode::kBlend ? "BLEND" : "OPAQUE";
}

std::string texture_desc(const Texture& t) {
  if (t.uri.empty()) return "-";
  if (!t.image) return t.uri + " (not loaded)";
  return std::to_string(t.image->width()) + "x" + std::to_string(t.image->height());
}

nlohmann::json vec_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

std::vector<int> faces_per_material(const Model& model) {
  std::vector<int> count(model.materials.size(), 0);
  for (const FaceSource& s : model.mesh.face_source)
    if (s.material >= 0 && s.material < static_cast<int>(count.size())) ++count[static_cast<std::size_t>(s.material)];
  return count;
}

}  // namespace

std::string model_summary_json(const Model& model) {
  const Eigen::AlignedBox3d box = bounds(model.mesh);
  const std::vector<int> faces = faces_per_material(model);
  nlohmann::json materials = nlohmann::json::array();
  for (std::size_t i = 0; i < model.materials.size(); ++i) {
    const SourceMaterial& m = model.materials[i];
    materials.push_back({{"index", i},
                         {"name", m.name},
                         {"faces", faces[i]},
                         {"base_color", {m.base_color[0], m.base_color[1], m.base_color[2], m.base_color[3]}},
                         {"metallic", m.metallic},
                         {"roughness", m.roughness},
                         {"alpha_mode", alpha_name(m.alpha_mode)},
                         {"transmission", m.transmission},
                         {"base_color_texture", texture_desc(m.base_color_texture)},
                         {"metallic_roughness_texture", texture_desc(m.metallic_roughness_texture)}});
  }
  const nlohmann::json j = {{"path", model.info.path},
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
  return detail::json_text(j, 2);
}

std::string model_summary_text(const Model& model) {
  const Eigen::AlignedBox3d box = bounds(model.mesh);
  const std::vector<int> faces = faces_per_material(model);
  std::ostringstream out;
  out << std::setprecision(4);
  out << model.info.path << " (" << model.info.format << ")\n"
      << "  frame:      " << model.info.unit_scale_m << " m per file unit, up axis " << model.info.up_axis
      << (model.info.file_to_model.topLeftCorner<3, 3>().isDiagonal() ? "" : " -> +Z") << "\n"
      << "  meshes:     " << model.info.num_source_meshes << " source meshes, " << model.primitives.size()
      << " placed in the scene\n"
      << "  faces:      " << model.mesh.num_faces() << " triangles (" << model.info.num_degenerate_faces
      << " degenerate), " << model.mesh.num_vertices() << " vertices, UVs " << (model.mesh.has_uvs() ? "yes" : "no")
      << "\n"
      << "  bounds (m): min (" << box.min().transpose() << ")  max (" << box.max().transpose() << ")  size ("
      << box.sizes().transpose() << ")\n"
      << "  area:       " << surface_area(model.mesh) << " m^2\n"
      << "  materials:  " << model.materials.size() << "\n";
  for (std::size_t i = 0; i < model.materials.size(); ++i) {
    const SourceMaterial& m = model.materials[i];
    out << "    [" << i << "] '" << m.name << "'  faces " << faces[i] << "  base (" << m.base_color.transpose()
        << ")  metallic " << m.metallic << "  roughness " << m.roughness << "  " << alpha_name(m.alpha_mode);
    if (m.transmission > 0.f) out << "  transmission " << m.transmission;
    out << "  textures: base " << texture_desc(m.base_color_texture) << ", metallic-roughness "
        << texture_desc(m.metallic_roughness_texture) << "\n";
  }
  for (const std::string& w : model.info.warnings) out << "  warning: " << w << "\n";
  return out.str();
}

}  // namespace g2p
