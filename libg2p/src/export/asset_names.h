// Private: the file and element names the exporters share.
#pragma once

#include <string>

#include "g2p/export.h"

namespace g2p::detail {

// "part_0_Wood_hull_3": hull 3 of a part, as a mesh, a geom and a file stem.
inline std::string hull_name(const AssetPart& part, std::size_t hull) {
  return part.name + "_hull_" + std::to_string(hull);
}

}  // namespace g2p::detail
