// Closed test meshes for the decompose stage: convex solids, and concave
// ones where one hull is a poor collision shape (a bowl, a U channel, a
// chair-like frame).
#pragma once

#include <array>
#include <vector>

#include "g2p/mesh.h"

namespace g2p::test {

// An axis-aligned box from `lo` to `hi`, 12 triangles, outward.
Mesh box_mesh(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi);

// The boundary of a union of grid cells (cells[z][y][x] != 0), each `cell_m`
// wide, its corner at the origin: one closed, outward surface (cells must
// not touch along an edge only).
Mesh cells_mesh(const std::vector<std::vector<std::vector<int>>>& cells, float cell_m);

// A surface of revolution about +z from a closed profile of (radius, z)
// points whose first and last points lie on the axis; outward.
Mesh revolve(const std::vector<std::array<double, 2>>& profile, int segments);

// A hemispherical bowl with a thick wall: outer radius `outer_m`, wall
// `wall_m`, standing on z = 0, open at the top (z = outer_m).
Mesh bowl_mesh(double outer_m, double wall_m, int segments = 48);

// A U channel of `cell_m` cells: two walls on a base, 5 cells wide.
Mesh u_channel_mesh(float cell_m);

}  // namespace g2p::test
