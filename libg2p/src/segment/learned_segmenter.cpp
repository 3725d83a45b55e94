// The `learned` segmenter: a trained network (the `onnx` backend) where the
// model's names and PBR channels say nothing, the `pbr` backend where they
// do. Rule, per pixel: the face seen there has a source material; when that
// material's name (or its base-colour texture's file name) names a material
// class outright (material_name_evidence >= `names` threshold for one class,
// none other above 0.5), or its PBR values were authored (a metallic-roughness
// texture, transmission, or metallic/roughness other than glTF's defaults of
// 1), the pixel takes `pbr`'s labels and probabilities; otherwise the
// network's. Names and authored PBR, where present, are right far more often
// than the network (docs/accuracy.md); image-to-3D meshes carry neither, and
// then the network decides everything. A model whose every material is named
// or authored is labelled by `pbr` alone: the network is not run, so such
// models cost what `pbr` costs.
//
// Settings: model_card = FILE (default: the network libg2p ships, found in
// $G2P_MODEL_DIR, the source tree's libg2p/data/models or the installed
// share/g2p/models); flip = on|off (the network's test-time mirroring, see
// onnx_segmenter.cpp; default off); names = threshold in (0, 1] (default 0.9) or "off" (the
// network alone); pbr = on (default) or off (authored PBR values do not count).
#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "core/settings.h"
#include "segment/backends.h"

namespace g2p {
namespace {

constexpr const char* kShippedCard = "g2p-materials.json";

// The shipped network's card, or "" when none is found.
std::string shipped_model_card() {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("G2P_MODEL_DIR"); env != nullptr && *env != '\0') dirs.emplace_back(env);
#ifdef G2P_SOURCE_MODEL_DIR
  dirs.emplace_back(G2P_SOURCE_MODEL_DIR);
#endif
#ifdef G2P_INSTALL_MODEL_DIR
  dirs.emplace_back(G2P_INSTALL_MODEL_DIR);
#endif
  for (const std::string& d : dirs) {
    std::error_code ec;
    const std::filesystem::path card = std::filesystem::path(d) / kShippedCard;
    if (std::filesystem::is_regular_file(card, ec)) return card.string();
  }
  return {};
}

class LearnedSegmenter final : public Segmenter {
 public:
  Status configure(const BackendSettings& settings) override {
    BackendSettings network;
    for (const auto& [key, value] : settings) {
      if (key == "model_card" || key == "flip") {
        network[key] = value;
      } else if (key == "names") {
        double v = 0;
        if (value == "off")
          threshold_ = 2.0;  // never reached
        else if (detail::parse_double(value, v) && v > 0 && v <= 1)
          threshold_ = v;
        else
          return Status::InvalidArgument("learned: names needs a threshold in (0, 1] or 'off', got '" + value + "'");
      } else if (key == "pbr" && (value == "on" || value == "off")) {
        trust_pbr_ = value == "on";
      } else {
        return Status::InvalidArgument("learned: bad setting " + key + "=" + value +
                                       " (known: model_card=FILE, flip=on|off, names=THRESHOLD|off, pbr=on|off)");
      }
    }
    if (network.count("model_card") == 0) {
      const std::string card = shipped_model_card();
      if (card.empty()) return Status::Ok();  // set_model says what is missing
      network["model_card"] = card;
    }
    network_ = make_onnx_segmenter();
    G2P_RETURN_IF_ERROR(network_->configure(network));
    configured_ = true;
    return Status::Ok();
  }

  Status set_model(const Model& model, const MaterialTable& table) override {
    if (!configured_)
      return Status::InvalidArgument(
          "learned: no network: give its card (setting model_card=FILE), put the shipped g2p-materials.json and "
          "g2p-materials.onnx in $G2P_MODEL_DIR, or choose the weight-free segmenter pbr");
    G2P_RETURN_IF_ERROR(network_->set_model(model, table));
    G2P_RETURN_IF_ERROR(names_->set_model(model, table));
    model_ = &model;
    named_.assign(model.materials.size(), 0);
    for (std::size_t m = 0; m < model.materials.size(); ++m) {
      const SourceMaterial& mat = model.materials[m];
      std::string text = mat.name;
      if (!mat.base_color_texture.uri.empty()) text += " " + mat.base_color_texture.uri;
      std::vector<float> e = material_name_evidence(text, table);
      std::sort(e.begin(), e.end(), std::greater<float>());
      const bool named = !e.empty() && e[0] >= threshold_ && (e.size() < 2 || e[1] <= 0.5f);
      // PBR values an author set (not glTF's defaults): a metallic-roughness
      // texture, transmission, or metallic/roughness other than (1, 1).
      const bool authored_pbr = trust_pbr_ && (!mat.metallic_roughness_texture.empty() || mat.transmission > 0.f ||
                                               mat.metallic < 1.f || mat.roughness < 1.f);
      named_[m] = named || authored_pbr;
    }
    // Every face has a named or authored material: the network's labels would
    // be replaced everywhere (faces without a material keep the network's).
    const std::vector<FaceSource>& sources = model.mesh.face_source;
    all_named_ = !sources.empty() && static_cast<int>(sources.size()) == model.mesh.num_faces() &&
                 std::all_of(sources.begin(), sources.end(), [&](const FaceSource& f) {
                   return f.material >= 0 && f.material < static_cast<int>(named_.size()) &&
                          named_[static_cast<std::size_t>(f.material)] != 0;
                 });
    return Status::Ok();
  }

  Status segment_into(const View& view, LabelMap& out) const override {
    if (model_ == nullptr) return Status::InvalidArgument("learned: set_model first");
    if (all_named_) return names_->segment_into(view, out);  // the network would be overwritten everywhere
    G2P_RETURN_IF_ERROR(network_->segment_into(view, out));
    if (std::none_of(named_.begin(), named_.end(), [](char n) { return n != 0; })) return Status::Ok();
    LabelMap by_name;
    G2P_RETURN_IF_ERROR(names_->segment_into(view, by_name));
    const Mesh& mesh = model_->mesh;
    const bool probabilities = !out.probabilities.empty() && !by_name.probabilities.empty() &&
                               out.probabilities.channels() == by_name.probabilities.channels();
    for (int y = 0; y < view.face_id.height(); ++y)
      for (int x = 0; x < view.face_id.width(); ++x) {
        const int f = view.face_id.at(x, y);
        if (f < 0 || mesh.face_source.empty()) continue;
        const int m = mesh.face_source[static_cast<std::size_t>(f)].material;
        if (m < 0 || m >= static_cast<int>(named_.size()) || !named_[static_cast<std::size_t>(m)]) continue;
        out.labels.at(x, y) = by_name.labels.at(x, y);
        if (probabilities)
          std::copy_n(by_name.probabilities.pixel(x, y), by_name.probabilities.channels(),
                      out.probabilities.pixel(x, y));
      }
    return Status::Ok();
  }

 private:
  std::unique_ptr<Segmenter> network_;
  std::unique_ptr<Segmenter> names_ = make_pbr_segmenter();
  bool configured_ = false;
  double threshold_ = 0.9;
  bool trust_pbr_ = true;
  const Model* model_ = nullptr;
  std::vector<char> named_;  // per source material: its name names a class
  bool all_named_ = false;   // every material is: `pbr` labels the whole model
};

}  // namespace

std::unique_ptr<Segmenter> make_learned_segmenter() { return std::make_unique<LearnedSegmenter>(); }

}  // namespace g2p
