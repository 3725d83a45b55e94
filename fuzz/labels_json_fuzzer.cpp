// libFuzzer target: the JSON readers of ground truth and saved views, on
// arbitrary bytes: material_labels_from_json (labels.json, as `g2p eval` and
// the oracle segmenter read it) and cameras_from_json (views/cameras.json, as
// `g2p segment` and `g2p project` read it back).
#include <cstddef>
#include <cstdint>
#include <string>

#include "g2p/materials.h"
#include "g2p/render.h"
#include "g2p/segment.h"
#include "model_invariants.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const g2p::MaterialTable& table = g2p::MaterialTable::paper_default();
  // The shared assets' keys, and a model with a handful of materials.
  for (const char* key : {"Avocado", "SheenChair", "WaterBottle"}) {
    constexpr int kMaterials = 4;
    g2p::Result<std::vector<int>> labels = g2p::material_labels_from_json(text, key, table, kMaterials);
    if (!labels.ok()) continue;
    if (labels->size() != static_cast<std::size_t>(kMaterials)) g2p::fuzz::violated("labels: not one per material");
    for (int l : *labels)
      if (l != g2p::kUnknownLabel && !table.valid_label(l)) g2p::fuzz::violated("labels: outside the table");
  }
  g2p::Result<std::vector<g2p::Camera>> cameras = g2p::cameras_from_json(text);
  if (cameras.ok()) {
    for (const g2p::Camera& c : *cameras) {
      if (!c.validate().ok()) g2p::fuzz::violated("cameras: a camera that was read does not validate");
    }
    // What was read writes back and reads again to the same views.
    g2p::Result<std::vector<g2p::Camera>> again = g2p::cameras_from_json(g2p::cameras_to_json(*cameras));
    if (!again.ok() || again->size() != cameras->size()) g2p::fuzz::violated("cameras: no round trip");
  }
  return 0;
}
