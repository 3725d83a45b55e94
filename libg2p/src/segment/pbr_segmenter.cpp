// The `pbr` segmenter: a material class per pixel from the evidence an asset
// carries, with no learned weights. Each class gets a score, the sum of:
//
//   prior     base rates of household objects (wood, fabric, plastic and metal
//             are common; organic, paper and "other" rare);
//   names     4 x the lexicon evidence (material_lexicon.cpp) of the source
//             material's name and external texture file name, and 0.7 of that
//             for the source mesh and node names ("SheenChair_wood"). A prefix
//             that all material (or all mesh, or all node) names share names
//             the object, not a material ("GlamVelvetSofa_feet" is not
//             velvet): its words count a quarter, the rest of each name fully;
//   metallic  metallic >= 0.5 pushes Metal up to +4 and the rest down; a
//             dielectric pushes Metal down up to -2.5 (the glTF metallic channel
//             is physically meaningful: metals have no diffuse colour);
//   glass     transmission t pushes every class down by t, then Glass up by
//             6t and Plastic by 2.5t (net +5t and +1.5t); an opacity a below 1
//             (BLEND) adds 3(1 - a) to Glass and (1 - a) to Plastic
//             (see-through solids are glass far more often than anything else);
//   roughness smooth dielectrics (roughness < 0.35) lean to Plastic, Ceramic
//             and Glass and away from Fabric and Paper; rough ones (> 0.6) to
//             Fabric, Stone, Paper and Rubber and away from Glass and Ceramic;
//   colour    brown/orange hues (10-50 deg, saturated, not bright) to Wood and
//             Leather; near-black to Rubber; near-white to Ceramic and Paper;
//             neutral grey to Stone; saturated colours to Plastic, Fabric and
//             Organic; greens (70-160 deg) to Organic;
//   texture   a base-colour texture with strong luminance variation (grain) to
//             Wood, Stone and Fabric; flat colour to Plastic and Metal.
//
// Per pixel the metallic, roughness, transmission, opacity and colour come from
// the renderer's material buffers (textures included); without them, from the
// material's factors; without a material, from the RGB pixel. Probabilities
// are the softmax of the scores divided by `temperature`. The weights are
// hand-set from the physics of the channels and the glTF conventions, not
// fitted to the shared assets (docs/accuracy.md measures them there).
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "g2p/segment.h"
#include "segment/backends.h"
#include "segment/material_lexicon.h"

namespace g2p {
namespace {

enum Paper { kWood, kRubber, kFabric, kOrganic, kLeather, kMetal, kPaperC, kPlastic, kGlass, kCeramic, kStone, kOther };
constexpr int kPaperClasses = 12;
using Scores = std::array<float, kPaperClasses>;

constexpr Scores kPrior = {0.4f, -0.6f, 0.3f, -0.6f, -0.4f, 0.3f, -0.6f, 0.4f, -0.3f, -0.3f, -0.5f, -1.0f};
constexpr float kNameWeight = detail::kPbrNameWeight;
constexpr float kMeshNameShare = 0.7f;
constexpr float kSharedPrefixShare = 0.25f;

struct Appearance {
  Eigen::Vector3f color = Eigen::Vector3f::Constant(0.5f);  // linear
  float opacity = 1.f;
  float metallic = -1.f;   // -1 = unknown
  float roughness = -1.f;  // -1 = unknown
  float transmission = 0.f;
};

float srgb(float linear) {
  return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(std::max(linear, 0.f), 1.f / 2.4f) - 0.055f;
}

// Hue in degrees, saturation and value of an sRGB colour.
Eigen::Vector3f hsv(const Eigen::Vector3f& rgb) {
  const float mx = rgb.maxCoeff(), mn = rgb.minCoeff(), d = mx - mn;
  float h = 0.f;
  if (d > 1e-6f) {
    if (mx == rgb[0])
      h = 60.f * std::fmod((rgb[1] - rgb[2]) / d, 6.f);
    else if (mx == rgb[1])
      h = 60.f * ((rgb[2] - rgb[0]) / d + 2.f);
    else
      h = 60.f * ((rgb[0] - rgb[1]) / d + 4.f);
  }
  if (h < 0.f) h += 360.f;
  return {h, mx > 0.f ? d / mx : 0.f, mx};
}

void add_appearance(const Appearance& a, Scores& s) {
  if (a.metallic >= 0.f) {
    if (a.metallic >= 0.5f) {
      const float m = 2.f * (a.metallic - 0.5f);
      for (int c = 0; c < kPaperClasses; ++c) s[c] += c == kMetal ? 4.f * m : -1.f * m;
    } else {
      s[kMetal] -= 2.5f * 2.f * (0.5f - a.metallic);
    }
  }
  if (a.transmission > 0.1f) {
    for (int c = 0; c < kPaperClasses; ++c) s[c] -= a.transmission;
    s[kGlass] += 6.f * a.transmission;
    s[kPlastic] += 2.5f * a.transmission;
  }
  if (a.opacity < 0.95f) {
    s[kGlass] += 3.f * (1.f - a.opacity);
    s[kPlastic] += 1.f * (1.f - a.opacity);
  }
  if (a.roughness >= 0.f) {
    const float smooth = std::max(0.f, 0.35f - a.roughness) / 0.35f;
    const float rough = std::max(0.f, a.roughness - 0.6f) / 0.4f;
    s[kPlastic] += 0.8f * smooth, s[kCeramic] += 0.8f * smooth, s[kGlass] += 0.6f * smooth;
    s[kMetal] += 0.3f * smooth, s[kFabric] -= 1.5f * smooth, s[kPaperC] -= 1.f * smooth;
    s[kStone] -= 0.5f * smooth, s[kWood] -= 0.3f * smooth;
    s[kFabric] += 1.f * rough, s[kStone] += 0.5f * rough, s[kPaperC] += 0.5f * rough, s[kRubber] += 0.5f * rough;
    s[kWood] += 0.3f * rough, s[kOrganic] += 0.3f * rough, s[kPlastic] -= 0.5f * rough;
    s[kCeramic] -= 0.8f * rough, s[kGlass] -= 1.5f * rough, s[kMetal] -= 0.5f * rough;
  }
  const Eigen::Vector3f c(srgb(a.color[0]), srgb(a.color[1]), srgb(a.color[2]));
  const Eigen::Vector3f h = hsv(c);
  const bool metal = a.metallic >= 0.5f;
  const bool brown = h[0] >= 10.f && h[0] <= 50.f && h[1] >= 0.25f && h[1] <= 0.9f && h[2] >= 0.08f && h[2] <= 0.75f;
  if (brown) s[kWood] += 1.5f, s[kLeather] += 0.7f, s[kOrganic] += 0.3f;
  if (h[2] < 0.06f && !metal) s[kRubber] += 1.f, s[kPlastic] += 0.4f, s[kLeather] += 0.3f;
  if (h[2] > 0.85f && h[1] < 0.12f) s[kCeramic] += 1.f, s[kPaperC] += 0.8f, s[kPlastic] += 0.5f, s[kFabric] += 0.2f;
  if (h[1] < 0.12f && h[2] >= 0.2f && h[2] <= 0.85f && !metal) s[kStone] += 0.6f, s[kPlastic] += 0.3f;
  if (h[1] > 0.55f && h[2] > 0.25f && !brown) s[kPlastic] += 0.6f, s[kFabric] += 0.5f, s[kOrganic] += 0.4f;
  if (h[0] >= 70.f && h[0] <= 160.f && h[1] > 0.3f) s[kOrganic] += 0.8f;
}

// Splits names into the prefix they all share (the object's name when the
// author prefixed every name with it: "GlamVelvetSofa_feet") and the rest.
// The prefix ends at a separator (not inside a word); fewer than two names,
// or no shared prefix of at least 4 characters up to a separator: no prefix.
std::string split_common_prefix(std::vector<std::string>& names) {
  if (names.size() < 2) return {};
  std::size_t n = names[0].size();
  for (const std::string& s : names) {
    std::size_t k = 0;
    while (k < n && k < s.size() && s[k] == names[0][k]) ++k;
    n = k;
  }
  while (n > 0 && std::isalnum(static_cast<unsigned char>(names[0][n - 1]))) --n;  // back to a separator
  if (n < 4) return {};
  std::string prefix = names[0].substr(0, n);
  for (std::string& s : names) s = s.substr(n);
  return prefix;
}

// Luminance standard deviation of a texture on a coarse grid (grain).
float texture_grain(const Texture& t) {
  if (t.empty()) return -1.f;
  const ImageU8& img = *t.image;
  const int step = std::max(1, std::max(img.width(), img.height()) / 64);
  double sum = 0, sum2 = 0;
  int n = 0;
  for (int y = 0; y < img.height(); y += step) {
    for (int x = 0; x < img.width(); x += step) {
      const std::uint8_t* p = img.pixel(x, y);
      const double l = (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0;
      sum += l, sum2 += l * l, ++n;
    }
  }
  const double mean = sum / n;
  return static_cast<float>(std::sqrt(std::max(0.0, sum2 / n - mean * mean)));
}

class PbrSegmenter final : public Segmenter {
 public:
  SettingsSpec settings() override {
    return SettingsSpec("pbr")
        .flag("names", use_names_, "material, texture, mesh and node names count as evidence")
        .number("temperature", temperature_, Range::above(0), "", "softness of the class probabilities");
  }

  Status set_model(const Model& model, const MaterialTable& table) override {
    model_ = &model;
    table_ = &table;
    to_table_.assign(kPaperClasses, kUnknownLabel);
    const char* names[kPaperClasses] = {"Wood",  "Rubber",  "Fabric", "Organic", "Leather", "Metal",
                                        "Paper", "Plastic", "Glass",  "Ceramic", "Stone",   "Other"};
    for (int c = 0; c < kPaperClasses; ++c) to_table_[c] = table.find(names[c]);

    // Per source material: name evidence and texture statistics, once.
    material_scores_.assign(model.materials.size(), std::vector<float>(static_cast<std::size_t>(table.size()), 0.f));
    for (std::size_t m = 0; m < model.materials.size(); ++m) {
      const SourceMaterial& mat = model.materials[m];
      Scores s{};
      const float grain = texture_grain(mat.base_color_texture);
      if (grain < 0.f) {
        s[kPlastic] += 0.3f, s[kMetal] += 0.1f;
      } else {
        const float g = std::clamp((grain - 0.04f) / 0.12f, 0.f, 1.f);
        s[kWood] += 0.6f * g, s[kStone] += 0.5f * g, s[kFabric] += 0.4f * g, s[kOrganic] += 0.3f * g;
        s[kPlastic] += 0.3f * (1.f - g), s[kMetal] += 0.2f * (1.f - g);
      }
      scatter(s, material_scores_[m]);
    }
    mesh_scores_.clear();
    if (use_names_) {
      detail::NameScores evidence = detail::pbr_name_scores(model, table);
      for (std::size_t m = 0; m < model.materials.size(); ++m)
        for (std::size_t c = 0; c < material_scores_[m].size(); ++c) material_scores_[m][c] += evidence.material[m][c];
      mesh_scores_ = std::move(evidence.mesh);
    }
    return Status::Ok();
  }

  // Names, textures and authored values decide, never the image alone.
  std::vector<std::uint8_t> image_decided_faces() const override {
    return std::vector<std::uint8_t>(model_ == nullptr ? 0 : model_->mesh.triangles.size(), 0);
  }

  Status segment_into(const View& view, LabelMap& out) const override {
    if (table_ == nullptr) return Status::InvalidArgument("pbr: set_model() first");
    const int w = view.face_id.width(), h = view.face_id.height();
    if (w == 0 || view.face_id.channels() != 1) return Status::InvalidArgument("pbr: the view has no face-ID buffer");
    const bool buffers =
        view.base_color.width() == w && view.metallic_roughness.width() == w && view.transmission.width() == w;
    const bool has_rgb = view.rgb.width() == w && view.rgb.height() == h;
    const int k = table_->size();
    out.labels.reset(w, h, 1, kUnknownLabel);
    out.probabilities.reset(w, h, k, 0.f);
    std::vector<float> score(static_cast<std::size_t>(k));
    const Mesh& mesh = model_->mesh;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const int face = view.face_id.at(x, y);
        if (face < 0) continue;
        if (face >= mesh.num_faces())
          return Status::InvalidArgument("pbr: face ID " + std::to_string(face) + " is not a face of the model");
        const FaceSource* src = mesh.face_source.empty() ? nullptr : &mesh.face_source[static_cast<std::size_t>(face)];
        const int m = src != nullptr && src->material >= 0 && src->material < static_cast<int>(model_->materials.size())
                          ? src->material
                          : -1;
        Appearance a;
        if (buffers) {
          for (int c = 0; c < 3; ++c) a.color[c] = view.base_color.at(x, y, c);
          a.opacity = view.base_color.at(x, y, 3);
          a.metallic = view.metallic_roughness.at(x, y, 0);
          a.roughness = view.metallic_roughness.at(x, y, 1);
          a.transmission = view.transmission.at(x, y);
        } else if (m >= 0) {
          const SourceMaterial& mat = model_->materials[static_cast<std::size_t>(m)];
          a.color = mat.base_color.head<3>();
          a.opacity = mat.alpha_mode == AlphaMode::kBlend ? mat.base_color[3] : 1.f;
          a.metallic = mat.metallic;
          a.roughness = mat.roughness;
          a.transmission = mat.transmission;
        } else if (has_rgb) {
          for (int c = 0; c < 3; ++c) a.color[c] = std::pow(view.rgb.at(x, y, c) / 255.f, 2.2f);
        }
        Scores s = kPrior;
        add_appearance(a, s);
        std::fill(score.begin(), score.end(), 0.f);
        scatter(s, score);
        if (m >= 0) {
          const std::vector<float>& ms = material_scores_[static_cast<std::size_t>(m)];
          for (int c = 0; c < k; ++c) score[c] += ms[c];
        }
        if (src != nullptr && src->mesh >= 0 && static_cast<std::size_t>(src->mesh) < mesh_scores_.size()) {
          const std::vector<float>& ns = mesh_scores_[static_cast<std::size_t>(src->mesh)];
          for (std::size_t c = 0; c < ns.size(); ++c) score[c] += ns[c];
        }
        // Softmax with temperature.
        float best = score[0];
        int label = 0;
        for (int c = 1; c < k; ++c)
          if (score[c] > best) best = score[c], label = c;
        float sum = 0.f;
        float* p = out.probabilities.pixel(x, y);
        for (int c = 0; c < k; ++c) sum += p[c] = std::exp((score[c] - best) / temperature_);
        for (int c = 0; c < k; ++c) p[c] /= sum;
        out.labels.at(x, y) = label;
      }
    }
    return Status::Ok();
  }

 private:
  // Adds paper-class scores to the table's classes (classes the table lacks drop out).
  void scatter(const Scores& s, std::vector<float>& out) const {
    for (int c = 0; c < kPaperClasses; ++c)
      if (to_table_[c] != kUnknownLabel) out[static_cast<std::size_t>(to_table_[c])] += s[c];
  }

  bool use_names_ = true;
  float temperature_ = 1.f;
  const Model* model_ = nullptr;
  const MaterialTable* table_ = nullptr;
  std::vector<int> to_table_;
  std::vector<std::vector<float>> material_scores_;  // per source material, per table class
  std::vector<std::vector<float>> mesh_scores_;      // per source mesh, per table class
};

}  // namespace

detail::NameScores detail::pbr_name_scores(const Model& model, const MaterialTable& table) {
  const std::size_t k = static_cast<std::size_t>(table.size());
  NameScores out;
  std::vector<std::string> material_names;
  for (const SourceMaterial& mat : model.materials) material_names.push_back(mat.name);
  const std::vector<float> material_shared = name_evidence(split_common_prefix(material_names), table);
  for (std::size_t m = 0; m < model.materials.size(); ++m) {
    const SourceMaterial& mat = model.materials[m];
    std::string text = material_names[m];
    for (const Texture* t : {&mat.base_color_texture, &mat.metallic_roughness_texture})
      if (!t->uri.empty() && t->uri[0] != '*') text += " " + std::filesystem::path(t->uri).stem().string();
    const std::vector<float> e = name_evidence(text, table);
    std::vector<float>& row = out.material.emplace_back(k, 0.f);
    for (std::size_t c = 0; c < k; ++c) row[c] = kNameWeight * std::max(e[c], kSharedPrefixShare * material_shared[c]);
  }
  std::vector<std::string> mesh_names, node_names;
  for (const SourcePrimitive& p : model.primitives) {
    mesh_names.push_back(p.mesh_name);
    node_names.push_back(p.node_name);
  }
  const std::string mesh_prefix = split_common_prefix(mesh_names);
  const std::string node_prefix = split_common_prefix(node_names);
  const std::vector<float> shared = name_evidence(mesh_prefix + " " + node_prefix, table);
  for (std::size_t i = 0; i < model.primitives.size(); ++i) {
    const SourcePrimitive& p = model.primitives[i];
    if (p.mesh < 0) continue;
    if (static_cast<std::size_t>(p.mesh) >= out.mesh.size()) out.mesh.resize(static_cast<std::size_t>(p.mesh) + 1);
    const std::vector<float> e = name_evidence(mesh_names[i] + " " + node_names[i], table);
    std::vector<float>& row = out.mesh[static_cast<std::size_t>(p.mesh)];
    row.assign(k, 0.f);
    for (std::size_t c = 0; c < k; ++c)
      row[c] = kNameWeight * kMeshNameShare * std::max(e[c], kSharedPrefixShare * shared[c]);
  }
  return out;
}

std::unique_ptr<Segmenter> make_pbr_segmenter() { return std::make_unique<PbrSegmenter>(); }

}  // namespace g2p
