// Private: estimate_properties with the object's rays built by the caller.
// The properties stage may weigh the parts several times (the kind's hidden
// mass, the mass posterior); the rays of a million-triangle object take a
// quarter of a second to build, and are the same every time.
#pragma once

#include <vector>

#include "g2p/properties.h"

namespace g2p::detail {

// estimate_properties() with `object_rays` built from `object` (SurfaceRays::build).
Result<PropertiesReport> estimate_properties(const Mesh& object, const std::vector<Part>& parts,
                                             const Completion& completion, const MaterialTable& table,
                                             const PropertyEstimator& estimator, const std::vector<View>* views,
                                             const StageProgress& progress, const SurfaceRays& object_rays);

}  // namespace g2p::detail
