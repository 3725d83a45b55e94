// Private: factories of the built-in segmenters, registered by name in
// segmenter_registry().
#pragma once

#include <memory>

#include "g2p/segment.h"

namespace g2p {

std::unique_ptr<Segmenter> make_pbr_segmenter();
std::unique_ptr<Segmenter> make_onnx_segmenter();
std::unique_ptr<Segmenter> make_oracle_segmenter();
std::unique_ptr<Segmenter> make_learned_segmenter();

}  // namespace g2p
