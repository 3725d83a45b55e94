// The `oracle` segmenter: ground truth. Each pixel takes the class of the
// source material of the face it sees, from a labels.json-style file. For
// ablations (a perfect stage 2) and for testing later stages in isolation.
//
// Settings: labels = path of the JSON file (required); key = the entry under
// "models" (default: the model file's name without extension).
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "g2p/segment.h"
#include "segment/backends.h"

namespace g2p {

Result<std::vector<int>> material_labels_from_json(const std::string& json_text, const std::string& key,
                                                   const MaterialTable& table, int num_materials) {
  using nlohmann::json;
  const json doc = json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) return Status::ParseError("labels: not a JSON object");
  const json* labels = nullptr;
  if (auto models = doc.find("models"); models != doc.end() && models->is_object()) {
    auto entry = models->find(key);
    if (entry == models->end()) {
      std::string known;
      for (const auto& item : models->items()) known += (known.empty() ? "" : ", ") + item.key();
      return Status::NotFound("labels: no model '" + key + "' (known: " + known + ")");
    }
    if (entry->is_object() && entry->contains("labels")) labels = &(*entry)["labels"];
  } else if (auto bare = doc.find("labels"); bare != doc.end()) {
    labels = &*bare;
  }
  if (labels == nullptr || !labels->is_object())
    return Status::ParseError("labels: expected {\"models\": {KEY: {\"labels\": {...}}}} or {\"labels\": {...}}");
  std::vector<int> out(static_cast<std::size_t>(std::max(0, num_materials)), kUnknownLabel);
  for (const auto& item : labels->items()) {
    char* end = nullptr;
    const long index = std::strtol(item.key().c_str(), &end, 10);
    if (end == item.key().c_str() || *end != '\0' || index < 0)
      return Status::ParseError("labels: key '" + item.key() + "' is not a material index");
    if (!item.value().is_string())
      return Status::ParseError("labels: material " + item.key() + ": expected a class name");
    const std::string name = item.value().get<std::string>();
    if (name == "ignore" || name == "void") continue;
    const int label = table.find(name);
    if (label == kUnknownLabel)
      return Status::InvalidArgument("labels: material " + item.key() + ": class '" + name +
                                     "' is not in the material table '" + table.name() + "'");
    if (index < num_materials) out[static_cast<std::size_t>(index)] = label;
  }
  return out;
}

namespace {

class OracleSegmenter final : public Segmenter {
 public:
  SettingsSpec settings() override {
    return SettingsSpec("oracle")
        .text("labels", labels_path_, "the ground truth (labels.json form; required)")
        .text("key", key_, "the model's entry in it (default: the model file's name)")
        .check([this] {
          // Refused when made, before a run loads and renders anything.
          if (!labels_path_.empty()) return Status::Ok();
          return Status::InvalidArgument(
              "oracle: needs the setting labels=FILE.json (the ground truth, labels.json form)");
        });
  }

  Status set_model(const Model& model, const MaterialTable& table) override {
    if (labels_path_.empty()) return Status::InvalidArgument("oracle: needs the setting labels=FILE.json");
    std::ifstream in(labels_path_, std::ios::binary);
    if (!in) return Status::NotFound(labels_path_ + ": cannot open the labels file");
    std::ostringstream text;
    text << in.rdbuf();
    const std::string key = key_.empty() ? std::filesystem::path(model.info.path).stem().string() : key_;
    Result<std::vector<int>> labels =
        material_labels_from_json(text.str(), key, table, static_cast<int>(model.materials.size()));
    if (!labels.ok()) return labels.status().with_context(labels_path_);
    material_label_ = std::move(*labels);
    model_ = &model;
    num_classes_ = table.size();
    return Status::Ok();
  }

  // The ground truth decides, never the image.
  std::vector<std::uint8_t> image_decided_faces() const override {
    return std::vector<std::uint8_t>(model_ == nullptr ? 0 : model_->mesh.triangles.size(), 0);
  }

  Status segment_into(const View& view, LabelMap& out) const override {
    if (model_ == nullptr) return Status::InvalidArgument("oracle: set_model() first");
    const Mesh& mesh = model_->mesh;
    if (mesh.face_source.empty()) return Status::InvalidArgument("oracle: the model has no face provenance");
    const int w = view.face_id.width(), h = view.face_id.height();
    out.labels.reset(w, h, 1, kUnknownLabel);
    out.probabilities.reset(w, h, num_classes_, 0.f);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const int face = view.face_id.at(x, y);
        if (face < 0) continue;
        if (face >= mesh.num_faces())
          return Status::InvalidArgument("oracle: face ID " + std::to_string(face) + " is not a face of the model");
        const int m = mesh.face_source[static_cast<std::size_t>(face)].material;
        const int label = m >= 0 && m < static_cast<int>(material_label_.size()) ? material_label_[m] : kUnknownLabel;
        out.labels.at(x, y) = label;
        if (label >= 0) out.probabilities.at(x, y, label) = 1.f;
      }
    }
    return Status::Ok();
  }

 private:
  std::string labels_path_, key_;
  const Model* model_ = nullptr;
  int num_classes_ = 0;
  std::vector<int> material_label_;
};

}  // namespace

std::unique_ptr<Segmenter> make_oracle_segmenter() { return std::make_unique<OracleSegmenter>(); }

}  // namespace g2p
