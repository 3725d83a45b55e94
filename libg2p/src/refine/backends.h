// Private: factories of the built-in refiners, registered in refiner_registry().
#pragma once

#include <memory>

#include "g2p/refine.h"

namespace g2p {

std::unique_ptr<Refiner> make_smooth_refiner();
std::unique_ptr<Refiner> make_vlm_refiner();
std::unique_ptr<Refiner> make_regions_refiner();  // regions/regions_refiner.cpp

}  // namespace g2p
