// Private: factories of the built-in decomposers, registered in decomposer_registry().
#pragma once

#include <memory>

#include "g2p/decompose.h"

namespace g2p {

std::unique_ptr<Decomposer> make_voxel_cut_decomposer();
std::unique_ptr<Decomposer> make_hull_decomposer();
std::unique_ptr<Decomposer> make_hacd_decomposer();  // only with G2P_WITH_HACD

}  // namespace g2p
