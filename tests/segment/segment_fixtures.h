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

}  // namespace g2p::test
