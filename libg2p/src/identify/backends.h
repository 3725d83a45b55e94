// Private: factories of the built-in identifiers, registered in
// identifier_registry().
#pragma once

#include <memory>

#include "g2p/identify.h"

namespace g2p::detail {

std::unique_ptr<Identifier> make_detector_identifier();  // detector_identifier.cpp
std::unique_ptr<Identifier> make_vlm_identifier();       // vlm_identifier.cpp

}  // namespace g2p::detail
