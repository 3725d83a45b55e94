// The render stage's backend registry, with the built-ins registered explicitly.
#include "backends.h"

namespace g2p {

Registry<Renderer>& renderer_registry() {
  static Registry<Renderer>* registry = [] {
    auto* r = new Registry<Renderer>("renderer");  // never destroyed: usable during static destruction
    (void)r->add("embree", &make_embree_renderer);
    return r;
  }();
  return *registry;
}

}  // namespace g2p
