// Private: a closed mesh on a voxel grid, for the voxel-cut search and for
// measuring how far collision hulls stand outside a part.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "g2p/mesh.h"

namespace g2p::detail {

struct VoxelGrid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // corner of cell (0, 0, 0), metres
  double cell_m = 0.0;                               // edge length of a cell
  Eigen::Vector3i size = Eigen::Vector3i::Zero();    // cells per axis
  std::vector<std::uint8_t> occupied;                // x fastest, then y, then z

  std::size_t index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(size.x()) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(size.y()) * k);
  }
  bool at(int i, int j, int k) const { return occupied[index(i, j, k)] != 0; }
  Eigen::Vector3d center(int i, int j, int k) const {
    return origin + cell_m * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
  }
};

// Cells whose centre lies inside the closed mesh (winding number along +z
// columns, so overlapping closed pieces count once) plus cells the surface
// passes through (sampled at half a cell), so thin walls are kept.
// `resolution` cells along the longest side; `pad` empty cells around.
VoxelGrid voxelize(const Mesh& closed, int resolution, int pad = 1);

// Marks the empty cells that no path of face-adjacent empty cells links to
// the grid's border (cavities enclosed by the part, which nothing outside
// can touch) as occupied. Returns how many.
long fill_enclosed(VoxelGrid& grid);

// Per cell, the distance from its centre to the nearest occupied cell's
// centre in metres (0 for occupied cells): an exact Euclidean distance
// transform (core/distance_transform.h).
std::vector<float> distance_to_occupied(const VoxelGrid& grid);

}  // namespace g2p::detail
