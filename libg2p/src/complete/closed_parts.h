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

// The faces of `part`, vertices within `weld_tolerance` (x the bounding-box
// diagonal of `mesh`) merged and compacted, triangles welding collapsed
// dropped. `source` (optional) receives the index in `mesh` of every face kept.
Mesh welded_part_faces(const Mesh& mesh, const Part& part, double weld_tolerance, std::vector<int>* source = nullptr);

// closed_part_surface(), and in `checks` the checks of the surface it
// returns (self-intersections included; no distance to a patch).
Mesh closed_part_surface_checked(const Mesh& mesh, const Part& part, double weld_tolerance, MeshChecks& checks);

}  // namespace g2p::detail
