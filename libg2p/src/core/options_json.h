// Private: the import and project options as JSON, one writer and one reader
// for the two files that hold them (manifest.json, options files).
#pragma once

#include <nlohmann/json.hpp>

#include "g2p/io.h"
#include "g2p/project.h"
#include "g2p/status.h"

namespace g2p::detail {

// {"unit_scale", "height_m", "longest_side_m", "up", "z_up", "textures", "strict"}.
nlohmann::json import_json(const ImportOptions& options);
// Reads those keys into `options` (nlohmann's exceptions for a missing key or a
// wrong type; an unknown up axis is an error naming "import.up").
Status read_import_json(const nlohmann::json& j, ImportOptions& options);

// {"vote", "weight_angle", "weight_footprint", "weld", "min_part_area", "merge_max_confidence"}.
nlohmann::json project_json(const ProjectOptions& options);
Status read_project_json(const nlohmann::json& j, ProjectOptions& options);

}  // namespace g2p::detail
