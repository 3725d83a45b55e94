// Private: what run.json and summary.html's 3D view say about one part.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>

#include "g2p/pipeline.h"

namespace g2p::detail {

// Part `i` of the run: part, material, faces, area_m2; closed and volume_m3
// once completed; density_kg_m3, structure, wall_thickness_m (0 when solid)
// and mass_kg once it has properties.
nlohmann::json part_summary_json(const PipelineResult& result, std::size_t i);

}  // namespace g2p::detail
