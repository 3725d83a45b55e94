// The object's real size at import: ImportOptions::height_m and
// longest_side_m, and the check for generator-normalised meshes.
#pragma once

#include "g2p/io.h"
#include "g2p/model.h"
#include "g2p/status.h"

namespace g2p::detail {

// Checks the size options (both at once, or with unit_scale, is an error).
Status check_size_options(const ImportOptions& options);

// Scales the imported model to the requested size, or, when none was given,
// records whether it looks normalised (ImportInfo::looks_normalised) and warns.
// Runs after the scene is flattened and before the extent guard.
Status apply_real_size(const ImportOptions& options, Model& model);

// Whether sides (metres) look like an image-to-3D generator's normalisation:
// the longest side within 2 % of 1 m or of 2 m (a unit cube or [-1, 1]^3).
bool looks_normalised(const Eigen::Vector3d& sides);

}  // namespace g2p::detail
