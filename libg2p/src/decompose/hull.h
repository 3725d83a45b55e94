// Private: convex hulls through Qhull (reentrant libqhull_r), shared by the
// decomposition backends and convex_hull().
#pragma once

#include <Eigen/Core>
#include <vector>

#include "g2p/mesh.h"
#include "g2p/status.h"

namespace g2p::detail {

// One hull as Qhull computes it.
struct QhullHull {
  std::vector<int> vertices;               // indices of the input points on the hull
  std::vector<Eigen::Vector3i> triangles;  // indices of input points, outward (only when triangulated)
  // Facet planes (n, offset): n . p + offset <= 0 inside; n unit length.
  std::vector<Eigen::Vector4d> planes;
};

// Runs Qhull on `n` points (x, y, z interleaved). `triangulate`: fill
// `triangles` (Qhull's Qt), else only `vertices` and `planes` (merged facets).
// Fails for fewer than 4 points, points on one plane or on a line.
Status run_qhull(const std::vector<double>& xyz, bool triangulate, QhullHull& out);

// convex_hull() with points that the reduction to `max_vertices` keeps
// first (indices into `points`; up to half the budget, those that are
// vertices of the full hull): the corners of a piece's cross-sections, so
// that two neighbouring hulls meet on their common cut.
Result<Mesh> convex_hull_keeping(const std::vector<Eigen::Vector3d>& points, int max_vertices,
                                 const std::vector<int>& keep);

}  // namespace g2p::detail
