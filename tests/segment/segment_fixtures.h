// Shared helpers of the segment tests: small generated models rendered into views.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "g2p/io.h"
#include "g2p/render.h"
#include "g2p/segment.h"
#include "support/gltf_builder.h"

namespace g2p::test {

// Renders `model` from `num_views` default views at `size` pixels.
std::vector<View> render(const Model& model, int num_views = 3, int size = 64);

// A glTF with one box per entry, side by side, each with its own material
// (name, colour, metallic, roughness, extra material JSON).
struct BoxMaterial {
  std::string name;
  Eigen::Vector4f color;
  float metallic, roughness;
  std::string extra_json = "{}";
};
Model boxes(const std::vector<BoxMaterial>& materials, const std::string& scratch_name);

// The most frequent label over the pixels whose face has source material `m`.
int majority_label(const Model& model, const std::vector<View>& views, const std::vector<LabelMap>& maps, int m);

// `source` as an image-to-3D generator would emit it: one material with a
// base-colour atlas of one flat tile per source material (its mean sRGB
// colour), each face's UVs at its material's tile, metallic and roughness at
// glTF's defaults (1, 1), every name removed (anonymize_names). Vertices are
// unshared per face so that each face reads its own tile.
Model one_atlas_material(const Model& source);

// Writes `model` (one material with a base-colour texture, as
// one_atlas_material makes it) as DIR/NAME.obj with NAME.mtl and NAME.png,
// positions as they are (libg2p's Z-up frame: read it back with up z).
// Returns the OBJ's path.
std::string write_atlas_obj(const Model& model, const std::string& dir, const std::string& name);

}  // namespace g2p::test
