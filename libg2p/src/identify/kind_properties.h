// Private: estimate_properties_of_kind with the object's rays built by the
// caller (properties/report.h), for the pipeline's properties stage, which
// weighs the parts up to six times.
#pragma once

#include <vector>

#include "g2p/identify.h"
#include "g2p/properties.h"

namespace g2p::detail {

Result<PropertiesReport> estimate_properties_of_kind(const Mesh& object, const std::vector<Part>& parts,
                                                     const Completion& completion, const MaterialTable& table,
                                                     const PropertyEstimator& estimator, const ObjectKind& kind,
                                                     const std::vector<View>* views, const StageProgress& progress,
                                                     const SurfaceRays& object_rays);

}  // namespace g2p::detail
