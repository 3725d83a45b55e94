// Private: small exact-in-double geometric predicates and a uniform grid of
// triangles for nearest-point and overlap queries, shared by the complete
// stage's backends and its checks.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "g2p/mesh.h"

namespace g2p::detail {

// Closest point to `p` on triangle (a, b, c), by the triangle's Voronoi
// regions (Ericson, Real-Time Collision Detection, 5.1.5).
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c);

// Whether the segment [p, q] meets triangle (a, b, c) away from the segment's
// ends (Moller-Trumbore, parameter in (eps, 1 - eps)); coplanar contact is not
// reported.
bool segment_hits_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                           const Eigen::Vector3d& b, const Eigen::Vector3d& c);

// Whether two triangles with no common vertex intersect: an edge of one
// crosses the other. Coplanar overlap is not reported.
bool triangles_intersect(const Eigen::Vector3d t0[3], const Eigen::Vector3d t1[3]);

// Triangles of a mesh binned on a uniform grid of about `triangles_per_cell`
// triangles per occupied cell.
class TriangleBins {
 public:
  TriangleBins(const Mesh& mesh, double triangles_per_cell = 4.0);

  // Distance from `p` to the nearest triangle (infinity for an empty mesh).
  // With `enough` >= 0 the search may stop at the first triangle closer than
  // that and return its distance (for maxima of minimum distances).
  double distance(const Eigen::Vector3d& p, double enough = -1.0) const;

  // Every pair (i < j) of triangles that share no vertex and intersect.
  std::vector<std::pair<int, int>> intersecting_pairs(int max_pairs) const;

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const;
  long long index(int i, int j, int k) const {
    return static_cast<long long>(i) + static_cast<long long>(dims_.x()) * (j + static_cast<long long>(dims_.y()) * k);
  }
  Eigen::Vector3d tri(int t, int corner) const;

  const Mesh& mesh_;
  Eigen::AlignedBox3d box_;
  double cell_ = 1.0;
  Eigen::Vector3i dims_ = Eigen::Vector3i::Ones();
  std::vector<int> start_;  // CSR over cells
  std::vector<int> items_;
};

}  // namespace g2p::detail
