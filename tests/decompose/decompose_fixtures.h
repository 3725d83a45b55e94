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

// A torus about +z through the origin: the tube's centre circle has radius
// `major_m`, the tube radius `minor_m`. Its hole is an opening, no cavity.
Mesh torus_mesh(double major_m, double minor_m, int segments = 48, int sides = 16);

// A mug: cup_mesh(0.04, 0.1, 0.005, 0.008) with a handle, the +x half of
// a torus in the xz plane about (0.0375, 0, 0.05) (the wall's middle;
// radius 0.03 m, tube 0.008 m) whose capped ends sit inside the wall: two
// overlapping closed surfaces, one part. The opening between handle and
// wall is about 20 mm across, centred at (0.05, 0, 0.05).
Mesh mug_mesh();

// A chair's back of `slats` vertical slats, one cell wide with two-cell gaps,
// between a bottom and a top rail one cell tall, 8 cells of slat between
// them, one cell deep (y); the gaps are openings. The middle of gap g
// (0-based) lies at x = (3 g + 2) cells, z = 5 cells, y = 0.5 cells.
Mesh slatted_back_mesh(int slats, float cell_m);

}  // namespace g2p::test
