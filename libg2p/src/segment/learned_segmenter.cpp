// The `learned` segmenter: a trained network (the `onnx` backend) where the
// model's names and PBR channels say nothing, the `pbr` backend where they
// do. Rule, per pixel: the face seen there takes `pbr`'s labels and
// probabilities when its names name a class outright, or when its material's
// PBR values were authored (read from a format with PBR materials, and a
// metallic-roughness texture, transmission, or metallic/roughness other than
// glTF's defaults of 1; not an OBJ's, which the importer derives); otherwise
// the network's. Names are read as `pbr` reads them (pbr_name_scores: the
// material's name and texture file names, a prefix shared by every material
// name counting a quarter, the mesh and node names at 0.7 of that weight); a
// face's names name a class when its summed name score reaches 4 x `names`
// (the score of that much evidence in the material's name) and no other
// class exceeds 4 x 0.5. Names and authored PBR, where present, are right far
// more often than the network (docs/accuracy.md); image-to-3D meshes carry
// neither, and then the network decides everything. A model whose every face
// is named or authored is labelled by `pbr` alone: the network is not run,
// nor loaded until a model needs it, so such models cost what `pbr` costs.
//
// `auto` decides per model instead of per face: `pbr` for a model with any
// face named or authored, the network everywhere on a model with none, as
// image-to-3D meshes arrive (docs/training.md, "A default that decides per
// model"). Neither is the default segmenter (`pbr` is: both lose to it on
// some named files). Neither backend runs the network on a model that `pbr`
// labels alone.
//
// Settings: model_card = FILE (default: the network libg2p ships, found in
// $G2P_MODEL_DIR, share/g2p/models beside libg2p, the source tree's
// libg2p/data/models or the install prefix's share/g2p/models); flip = on|off
// (the network's test-time mirroring, see onnx_segmenter.cpp; default off); names = threshold in (0, 1] (default 0.9)
// or "off" (the network alone); pbr = on (default) or off (authored PBR values do not count).
#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "core/settings.h"
#include "segment/backends.h"

namespace g2p {
namespace {

constexpr const char* kShippedCard = "g2p-materials.json";

}  // namespace

namespace detail {

std::string shipped_model_card() { return shipped_model_file(kShippedCard); }

bool pbr_authored(const SourceMaterial& mat) {
  return mat.pbr_from_file && (!mat.metallic_roughness_texture.empty() || mat.transmission > 0.f ||
                               mat.metallic < 1.f || mat.roughness < 1.f);
}

std::vector<char> faces_named(const Model& model, const MaterialTable& table, double threshold) {
  const NameScores scores = pbr_name_scores(model, table);
  const Mesh& mesh = model.mesh;
  const int k = table.size();
  std::vector<float> sum(static_cast<std::size_t>(k));
  std::vector<char> named(
      mesh.face_source.size() == static_cast<std::size_t>(mesh.num_faces()) ? mesh.face_source.size() : 0, 0);
  for (std::size_t f = 0; f < named.size(); ++f) {
    const FaceSource& src = mesh.face_source[f];
    std::fill(sum.begin(), sum.end(), 0.f);
    if (src.material >= 0 && src.material < static_cast<int>(model.materials.size()))
      for (int c = 0; c < k; ++c) sum[c] += scores.material[static_cast<std::size_t>(src.material)][c];
    if (src.mesh >= 0 && static_cast<std::size_t>(src.mesh) < scores.mesh.size() &&
        scores.mesh[static_cast<std::size_t>(src.mesh)].size() == sum.size())
      for (int c = 0; c < k; ++c) sum[c] += scores.mesh[static_cast<std::size_t>(src.mesh)][c];
    const auto top = std::max_element(sum.begin(), sum.end());
    if (top == sum.end() || *top < kPbrNameWeight * threshold) continue;
    bool alone = true;
    for (auto c = sum.begin(); c != sum.end(); ++c) alone &= c == top || *c <= kPbrNameWeight * 0.5f;
    named[f] = alone;
  }
  return named;
}

}  // namespace detail

namespace {

class LearnedSegmenter final : public Segmenter {
 public:
  explicit LearnedSegmenter(bool per_model) : per_model_(per_model), name_(per_model ? "auto" : "learned") {}

  SettingsSpec settings() override {
    return SettingsSpec(name_)
        .text("model_card", card_, "the network's card (g2p-materials.json); \"\" finds the shipped one")
        .flag("flip", flip_, "the network also reads each view mirrored")
        .number("names", threshold_, Range::above_to(0, 1), "",
                "name-evidence threshold for a face's names to name a class")
        .or_word("off", 2.0)
        .flag("pbr", trust_pbr_, "a material with authored PBR counts as named")
        .check([this] { return connect(); });
  }

  Status set_model(const Model& model, const MaterialTable& table) override {
    model_ = nullptr;
    G2P_RETURN_IF_ERROR(names_->set_model(model, table));
    // Where names speak, read as `pbr` reads them: the material's name and its
    // textures' file names (a prefix every material name shares counts a
    // quarter), plus 0.7 of that weight for the mesh and node names, in
    // `pbr`'s score units (4 per unit of evidence). A face is named when one
    // class reaches 4 x `names` and no other exceeds 4 x 0.5.
    std::vector<char> authored(model.materials.size(), 0);
    for (std::size_t m = 0; m < model.materials.size(); ++m)
      authored[m] = trust_pbr_ && detail::pbr_authored(model.materials[m]);
    named_ = detail::faces_named(model, table, threshold_);
    for (std::size_t f = 0; f < named_.size(); ++f) {
      const int material = model.mesh.face_source[f].material;
      if (material >= 0 && material < static_cast<int>(authored.size()) && authored[static_cast<std::size_t>(material)])
        named_[f] = 1;
    }
    // Every face named or authored: the network's labels would be replaced
    // everywhere. `auto`: any face is, and `pbr` labels the whole model; none
    // is, and the network labels all of it.
    const auto is_set = [](char n) { return n != 0; };
    all_named_ = per_model_ ? std::any_of(named_.begin(), named_.end(), is_set)
                            : !named_.empty() && std::all_of(named_.begin(), named_.end(), is_set);
    if (per_model_ && !all_named_) std::fill(named_.begin(), named_.end(), 0);
    if (!all_named_) {
      if (!configured_)
        return Status::InvalidArgument(
            name_ +
            ": no network for a model whose names and PBR say nothing: give its card (setting model_card=FILE), put "
            "the shipped g2p-materials.json and g2p-materials.onnx in $G2P_MODEL_DIR, or choose the weight-free "
            "segmenter pbr");
      G2P_RETURN_IF_ERROR(network_->set_model(model, table));
    }
    model_ = &model;
    return Status::Ok();
  }

  // The network decides the faces names and authored PBR leave open.
  std::vector<std::uint8_t> image_decided_faces() const override {
    if (model_ == nullptr) return {};
    std::vector<std::uint8_t> image(model_->mesh.triangles.size(), all_named_ ? 0 : 1);
    if (!all_named_)
      for (std::size_t f = 0; f < image.size() && f < named_.size(); ++f) image[f] = named_[f] ? 0 : 1;
    return image;
  }

  Status segment_into(const View& view, LabelMap& out) const override {
    if (model_ == nullptr) return Status::InvalidArgument(name_ + ": set_model first");
    if (all_named_) return names_->segment_into(view, out);  // the network would be overwritten everywhere
    G2P_RETURN_IF_ERROR(network_->segment_into(view, out));
    if (std::none_of(named_.begin(), named_.end(), [](char n) { return n != 0; })) return Status::Ok();
    LabelMap by_name;
    G2P_RETURN_IF_ERROR(names_->segment_into(view, by_name));
    const bool probabilities = !out.probabilities.empty() && !by_name.probabilities.empty() &&
                               out.probabilities.channels() == by_name.probabilities.channels();
    for (int y = 0; y < view.face_id.height(); ++y)
      for (int x = 0; x < view.face_id.width(); ++x) {
        const int f = view.face_id.at(x, y);
        if (f < 0 || f >= static_cast<int>(named_.size()) || !named_[static_cast<std::size_t>(f)]) continue;
        out.labels.at(x, y) = by_name.labels.at(x, y);
        if (probabilities)
          std::copy_n(by_name.probabilities.pixel(x, y), by_name.probabilities.channels(),
                      out.probabilities.pixel(x, y));
      }
    return Status::Ok();
  }

 private:
  // The network for the settings as they are: loaded by set_model, for the
  // first model that needs it. No card found: set_model says what is missing.
  Status connect() {
    BackendSettings network{{"model_card", card_}, {"flip", flip_ ? "on" : "off"}};
    if (card_.empty()) {
      const std::string card = detail::shipped_model_card();
      if (card.empty()) return Status::Ok();
      network["model_card"] = card;
    }
    std::unique_ptr<Segmenter> net = detail::make_deferred_onnx_segmenter();
    G2P_RETURN_IF_ERROR(net->configure(network));
    network_ = std::move(net);
    configured_ = true;
    return Status::Ok();
  }

  std::string card_;   // model_card ("" = the shipped card)
  bool flip_ = false;  // flip
  std::unique_ptr<Segmenter> network_;
  std::unique_ptr<Segmenter> names_ = make_pbr_segmenter();
  bool configured_ = false;
  bool per_model_ = false;  // `auto`
  std::string name_;
  double threshold_ = 0.9;
  bool trust_pbr_ = true;
  const Model* model_ = nullptr;
  std::vector<char> named_;  // per face: its names name a class, or its material's PBR was authored
  bool all_named_ = false;   // every face is: `pbr` labels the whole model
};

}  // namespace

std::unique_ptr<Segmenter> make_learned_segmenter() { return std::make_unique<LearnedSegmenter>(false); }
std::unique_ptr<Segmenter> make_auto_segmenter() { return std::make_unique<LearnedSegmenter>(true); }

}  // namespace g2p
