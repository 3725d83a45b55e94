// Example: a user-written segmenter plugged into the pipeline. This one knows
// nothing about names or PBR channels: it gives each pixel the class whose
// reference colour (a small palette the user supplies) is nearest to the
// pixel's base colour. Any Segmenter subclass, a neural network's included,
// plugs in the same way.
//
//   custom_segmenter MODEL
#include <g2p/g2p.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace {

class PaletteSegmenter final : public g2p::Segmenter {
 public:
  // Reference colours, linear RGB in [0, 1], by class name.
  explicit PaletteSegmenter(std::vector<std::pair<std::string, std::array<float, 3>>> palette)
      : palette_(std::move(palette)) {}

  g2p::Status set_model(const g2p::Model&, const g2p::MaterialTable& table) override {
    labels_.clear();
    for (const auto& [name, colour] : palette_) {
      const int label = table.find(name);
      if (label == g2p::kUnknownLabel) return g2p::Status::InvalidArgument("palette: no class named '" + name + "'");
      labels_.push_back(label);
    }
    return g2p::Status::Ok();
  }

  g2p::Status segment_into(const g2p::View& view, g2p::LabelMap& out) const override {
    if (view.base_color.empty())
      return g2p::Status::InvalidArgument(
          "palette: the view has no base-colour buffer (RenderOptions::material_buffers)");
    const int w = view.face_id.width(), h = view.face_id.height();
    out.labels.reset(w, h, 1, g2p::kUnknownLabel);
    out.probabilities.clear();  // this backend gives hard labels only
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (view.face_id.at(x, y) < 0) continue;  // background
        const float* c = view.base_color.pixel(x, y);
        float best = std::numeric_limits<float>::max();
        for (std::size_t k = 0; k < palette_.size(); ++k) {
          const auto& ref = palette_[k].second;
          const float d = std::pow(c[0] - ref[0], 2.f) + std::pow(c[1] - ref[1], 2.f) + std::pow(c[2] - ref[2], 2.f);
          if (d < best) best = d, out.labels.at(x, y) = labels_[k];
        }
      }
    return g2p::Status::Ok();
  }

 private:
  std::vector<std::pair<std::string, std::array<float, 3>>> palette_;
  std::vector<int> labels_;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s MODEL\n", argv[0]);
    return 2;
  }
  g2p::Pipeline pipeline;
  // Brown reads as wood, grey as metal (the hammer in examples/data).
  pipeline.set_segmenter(std::make_shared<PaletteSegmenter>(std::vector<std::pair<std::string, std::array<float, 3>>>{
      {"Wood", {0.40f, 0.20f, 0.08f}}, {"Metal", {0.55f, 0.55f, 0.57f}}}));
  g2p::Result<g2p::PipelineResult> r = pipeline.run_file(argv[1]);
  if (!r.ok()) {
    std::fprintf(stderr, "error: %s\n", r.status().to_string().c_str());
    return 1;
  }
  std::printf("segmenter: %s\n", r->stage(g2p::Stage::kSegment)->backend.c_str());
  for (std::size_t i = 0; i < r->projection.parts.size(); ++i) {
    const g2p::Part& part = r->projection.parts[i];
    std::printf("part %zu: %-8s %5zu faces, %.4f kg\n", i, r->table[part.label].name.c_str(), part.faces.size(),
                r->properties.parts[i].mass.mass_kg);
  }
  std::printf("total %.4f kg, centre of mass z = %.4f m\n", r->properties.object.mass_kg,
              r->properties.object.center_of_mass.z());
  return 0;
}
