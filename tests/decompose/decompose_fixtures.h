// Closed test meshes for the decompose stage: convex solids, and concave
// ones where one hull is a poor collision shape (a bowl, a U channel, a
// chair-like frame). Boxes and spheres are in support/gltf_builder.h.
#pragma once

#include <array>
#include <vector>

#include "g2p/mesh.h"

namespace g2p::test {

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

// A cup: a cylinder of radius `radius_m` and height `height_m` with a flat
// bottom `bottom_m` thick and a wall `wall_m` thick, standing on z = 0.
Mesh cup_mesh(double radius_m, double height_m, double wall_m, double bottom_m, int segments = 48);

// A chair-like frame of `cell_m` cells: four legs 8 cells tall, a seat 8 x 8
// cells and one cell thick on them (its top at 9 cells), a backrest 8 cells
// tall along the back edge (y = 7). One closed surface.
Mesh chair_mesh(float cell_m);

}  // namespace g2p::test
