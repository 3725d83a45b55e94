#include "segment/segment_fixtures.h"

#include <gtest/gtest.h>

#include "support/test_data.h"

namespace g2p::test {

std::vector<View> render(const Model& model, int num_views, int size) {
  ViewOptions vo;
  vo.num_views = num_views;
  vo.width = vo.height = size;
  auto renderer = std::move(*renderer_registry().create("embree"));
  Result<std::vector<View>> views = render_views(*renderer, model, *make_views(model.mesh, vo));
  EXPECT_TRUE(views.ok()) << views.status().to_string();
  return views.ok() ? std::move(*views) : std::vector<View>{};
}

Model boxes(const std::vector<BoxMaterial>& materials, const std::string& scratch_name) {
  GltfBuilder g;
  for (std::size_t i = 0; i < materials.size(); ++i) {
    const BoxMaterial& b = materials[i];
    const int m = g.add_material(b.name, b.color, b.metallic, b.roughness, -1, "{}", b.extra_json);
    std::vector<Eigen::Vector3f> p;
    std::vector<std::array<unsigned, 3>> t;
    const float x = 1.5f * static_cast<float>(i);
    box_geometry({x, 0.f, 0.f}, {x + 1.f, 1.f, 1.f}, p, t);
    g.add_node(g.add_mesh("box" + std::to_string(i), p, t, m));
  }
  const std::string dir = scratch_dir(scratch_name);
  g.write(dir + "/boxes.glb");
  Result<Model> model = load_model(dir + "/boxes.glb");
  EXPECT_TRUE(model.ok()) << model.status().to_string();
  return model.ok() ? std::move(*model) : Model{};
}

int majority_label(const Model& model, const std::vector<View>& views, const std::vector<LabelMap>& maps, int m) {
  std::map<int, int> votes;
  for (std::size_t v = 0; v < views.size(); ++v) {
    for (std::size_t i = 0; i < views[v].face_id.size(); ++i) {
      const int f = views[v].face_id.data()[i];
      if (f >= 0 && model.mesh.face_source[f].material == m) ++votes[maps[v].labels.data()[i]];
    }
  }
  int best = kUnknownLabel, count = 0;
  for (const auto& [label, n] : votes)
    if (n > count) best = label, count = n;
  return best;
}

}  // namespace g2p::test
