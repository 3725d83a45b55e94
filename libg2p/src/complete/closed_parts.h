// Private: a part's faces with coincident vertices merged, shared by
// closed_part_surface (is the part already closed?) and thin_part_shell
// (the surface a shell is built on), and closed_part_surface with the checks
// it made, for complete().
#pragma once

#include <vector>

#include "g2p/complete.h"
#include "g2p/mesh.h"
#include "g2p/project.h"

namespace g2p::detail {

// The weld distance of `mesh` for a weld tolerance: the tolerance times its
// bounding-box diagonal (metres). A loop over parts computes it once.
double weld_distance(const Mesh& mesh, double weld_tolerance);

// The faces of `part`, vertices within `weld_distance_m` (weld_distance())
// merged and compacted, triangles welding collapsed dropped. `source`
// (optional) receives the index in `mesh` of every face kept.
Mesh welded_part_faces(const Mesh& mesh, const Part& part, double weld_distance_m, std::vector<int>* source = nullptr);

// closed_part_surface(), and in `checks` the checks of the surface it
// returns (self-intersections included; no distance to a patch).
Mesh closed_part_surface_checked(const Mesh& mesh, const Part& part, double weld_distance_m, MeshChecks& checks);

}  // namespace g2p::detail
