// The Refiner base class, the "none" backend and the registry.
#include "g2p/refine.h"
#include "refine/backends.h"

namespace g2p {

Refiner::~Refiner() = default;

Status Refiner::configure(const BackendSettings& settings) {
  if (settings.empty()) return Status::Ok();
  return Status::InvalidArgument("this refiner takes no settings (got '" + settings.begin()->first + "')");
}

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
    auto* r = new Registry<Refiner>();  // never destroyed: usable during static destruction
    (void)r->add("smooth", &make_smooth_refiner);
    (void)r->add("vlm", [] { return make_vlm_refiner(); });
    (void)r->add("none", [] { return std::unique_ptr<Refiner>(std::make_unique<NoRefiner>()); });
    return r;
  }();
  return *registry;
}

Result<std::unique_ptr<Refiner>> make_refiner(const std::string& name, const BackendSettings& settings) {
  Result<std::unique_ptr<Refiner>> r = refiner_registry().create(name);
  if (!r.ok()) return r.status();
  G2P_RETURN_IF_ERROR((*r)->configure(settings));
  return r;
}

}  // namespace g2p
