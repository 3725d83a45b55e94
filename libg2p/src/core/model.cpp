#include "g2p/model.h"

namespace g2p {

ObjectSize object_size(const Model& model) {
  ObjectSize s;
  if (!model.mesh.positions.empty()) s.extent_m = bounds(model.mesh).sizes();
  s.scale_source = model.info.scale_source;
  s.metres_per_file_unit = model.info.unit_scale_m;
  s.looks_normalised = model.info.looks_normalised;
  return s;
}

void anonymize_names(Model& model) {
  for (std::size_t i = 0; i < model.materials.size(); ++i) {
    SourceMaterial& m = model.materials[i];
    m.name = "material_" + std::to_string(i);
    for (Texture* t : m.textures())
      if (!t->uri.empty() && t->uri[0] != '*') t->uri = "texture_" + std::to_string(i) + ".png";
  }
  for (SourcePrimitive& p : model.primitives) {
    p.mesh_name = "mesh_" + std::to_string(p.mesh);
    p.node_name = "node";
  }
}

void reduce_to_base_color(Model& model) {
  for (SourceMaterial& m : model.materials) {
    m.metallic = 1.f;
    m.roughness = 1.f;
    m.transmission = 0.f;
    m.metallic_roughness_texture = Texture{};
    m.normal_texture = m.occlusion_texture = m.emissive_texture = Texture{};
  }
}

}  // namespace g2p
