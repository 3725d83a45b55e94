// Private: quadric-error edge collapse (Garland & Heckbert 1997, "Surface
// simplification using quadric error metrics") for closed 2-manifold meshes:
// the part surfaces the partition completer extracts, and the closed parts the
// hacd decomposer thins before decomposing. Collapses keep the mesh a closed
// 2-manifold (link condition), never flip a triangle, and move no vertex
// farther than `max_error_m` from the planes of the triangles it replaces.
#pragma once

#include "g2p/mesh.h"

namespace g2p::detail {

// Returns the number of collapses made. The mesh must be closed and manifold;
// vertex and triangle order are not kept.
int simplify_closed_mesh(Mesh& mesh, double max_error_m);

}  // namespace g2p::detail
