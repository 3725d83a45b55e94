// The Segmenter base class and the backend registry.
#include "g2p/segment.h"
#include "segment/backends.h"

namespace g2p {

Segmenter::~Segmenter() = default;

SettingsSpec Segmenter::settings() { return SettingsSpec("this segmenter"); }

Status Segmenter::configure(const BackendSettings& settings) { return this->settings().apply(settings); }

std::vector<std::string> Segmenter::warnings() const { return {}; }
std::vector<std::uint8_t> Segmenter::image_decided_faces() const { return {}; }

Result<LabelMap> Segmenter::segment(const View& view) const {
  LabelMap out;
  G2P_RETURN_IF_ERROR(segment_into(view, out));
  return out;
}

Registry<Segmenter>& segmenter_registry() {
  static Registry<Segmenter>* registry = [] {
    auto* r = new Registry<Segmenter>("segmenter");  // never destroyed: usable during static destruction
    (void)r->add("pbr", &make_pbr_segmenter);
    (void)r->add("onnx", &make_onnx_segmenter);
    (void)r->add("oracle", &make_oracle_segmenter);
    (void)r->add("learned", &make_learned_segmenter);
    (void)r->add("auto", &make_auto_segmenter);
    (void)r->add("hybrid", &make_hybrid_segmenter);
    return r;
  }();
  return *registry;
}

}  // namespace g2p
