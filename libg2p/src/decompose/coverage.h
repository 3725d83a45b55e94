// Private: how much of a part's surface its collision hulls leave uncovered.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "g2p/mesh.h"

namespace g2p::detail {

// The exact distance from `p` to a closed, outward, convex triangle mesh
// (0 inside or on it).
double distance_to_convex(const Eigen::Vector3d& p, const Mesh& hull);

struct Uncovered {
  double mean_m = 0.0;  // over the area samples (0 where a hull holds one)
  double max_m = 0.0;   // over the area samples and the vertices checked
};

// Distances from the part's closed surface to the union of `hulls`: about
// `samples` points spread over the surface by area (every face gets its share
// of a stratified sequence) and, for a mesh of at most `samples` vertices,
// every vertex too (a low-poly part's corners are where a reduced hull
// retreats). Each point's distance is exact: the nearest hull's, 0 inside one.
Uncovered uncovered_distance(const Mesh& closed, const std::vector<Mesh>& hulls, int samples = 20000);

}  // namespace g2p::detail
