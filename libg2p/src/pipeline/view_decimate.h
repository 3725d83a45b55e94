// Private: fewer triangles for a viewer to draw (summary.html's 3D view).
#pragma once

#include <cstddef>
#include <vector>

#include "g2p/mesh.h"

namespace g2p::detail {

struct ViewMesh {
  Mesh mesh;                     // positions and triangles only
  std::vector<int> source_face;  // per triangle of `mesh`: a face of the input it stands for
};

// The faces `faces` of `mesh` as a mesh of their own with at most
// `max_triangles` triangles. Over the budget, vertex clustering: the vertices
// in each cell of a uniform grid over the faces' bounds merge into their mean,
// triangles that collapse are dropped and duplicates kept once; the grid
// coarsens until the budget holds. Works on any triangle soup (open, non-manifold),
// in time linear in the faces, for 1M+ triangle inputs.
ViewMesh view_mesh(const Mesh& mesh, const std::vector<int>& faces, std::size_t max_triangles);

}  // namespace g2p::detail
