// Private: polygon triangulation used by the importer.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <vector>

namespace g2p::detail {

// Triangulates one polygon (a simple polygon in 3D, possibly slightly
// non-planar) by ear clipping in the plane of its Newell normal. Appends
// triangles as local vertex indices, wound like the polygon. Convex and
// concave polygons are handled; a polygon that is not simple (self-crossing)
// still yields n - 2 triangles, by clipping the least bad corner when no ear
// is left.
void triangulate_polygon(const std::vector<Eigen::Vector3d>& points, std::vector<std::array<int, 3>>& triangles);

}  // namespace g2p::detail
