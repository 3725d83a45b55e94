// Private: factories of the built-in render backends, registered by name in
// renderer_registry().
#pragma once

#include <memory>

#include "g2p/render.h"

namespace g2p {

std::unique_ptr<Renderer> make_embree_renderer();

}  // namespace g2p
