// The Refiner base class, the "none" backend and the registry.
#include "g2p/refine.h"
#include "refine/backends.h"

namespace g2p {

Refiner::~Refiner() = default;

SettingsSpec Refiner::settings() { return SettingsSpec("this refiner"); }

Status Refiner::configure(const BackendSettings& settings) { return this->settings().apply(settings); }

namespace {

// Labels unchanged: the ablation without stage 4.
class NoRefiner final : public Refiner {
 public:
  Result<RefineResult> refine(const RefineInput& input) const override {
    if (input.labels == nullptr) return Status::InvalidArgument("refine: no labels");
    RefineResult r;
    r.labels = input.labels->label;
    r.notes.push_back("none: labels unchanged");
    return r;
  }
};

}  // namespace

Registry<Refiner>& refiner_registry() {
  static Registry<Refiner>* registry = [] {
    auto* r = new Registry<Refiner>("refiner");  // never destroyed: usable during static destruction
    (void)r->add("smooth", &make_smooth_refiner);
    (void)r->add("vlm", [] { return make_vlm_refiner(); });
    (void)r->add("regions", &make_regions_refiner);
    (void)r->add("none", [] { return std::unique_ptr<Refiner>(std::make_unique<NoRefiner>()); });
    return r;
  }();
  return *registry;
}

Status apply_refinement(const Mesh& mesh, const std::vector<int>& labels, const PartitionOptions& options,
                        Projection& projection) {
  const std::size_t n = static_cast<std::size_t>(mesh.num_faces());
  if (labels.size() != n || projection.labels.label.size() != n || projection.votes.total.size() != n)
    return Status::InvalidArgument("apply_refinement: " + std::to_string(labels.size()) + " labels for a mesh of " +
                                   std::to_string(n) + " faces, or a projection of another mesh");
  const std::vector<float> voted_confidence = projection.labels.confidence;
  projection.labels.label = labels;
  projection.parts =
      partition(mesh, projection.graph, projection.labels.label, projection.face_part, options, &voted_confidence);
  for (std::size_t f = 0; f < n; ++f) {
    const float* h = projection.votes.of(static_cast<int>(f));
    const int l = projection.labels.label[f];
    const float t = projection.votes.total[f];
    projection.labels.confidence[f] = h != nullptr && t > 0.f && l >= 0 ? h[l] / t : 0.f;
  }
  return Status::Ok();
}

}  // namespace g2p
