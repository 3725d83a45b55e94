// Ear-clipping triangulation (Meisters 1975, "Polygons have ears"), O(n^2),
// in the plane of the polygon's Newell normal (Newell's method, as in
// Sutherland, Sproull & Schumacker 1974).
#include "triangulate.h"

#include <limits>

namespace g2p::detail {
namespace {

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Whether p lies inside or on triangle abc (counter-clockwise).
bool in_triangle(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                 const Eigen::Vector2d& c) {
  return cross2(b - a, p - a) >= 0.0 && cross2(c - b, p - b) >= 0.0 && cross2(a - c, p - c) >= 0.0;
}

}  // namespace

void triangulate_polygon(const std::vector<Eigen::Vector3d>& points, std::vector<std::array<int, 3>>& triangles) {
  const int n = static_cast<int>(points.size());
  if (n < 3) return;
  if (n == 3) {
    triangles.push_back({0, 1, 2});
    return;
  }
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) normal += points[i].cross(points[(i + 1) % n]);
  if (normal.squaredNorm() == 0.0) {  // collinear or zero area: any fan is as good
    for (int i = 1; i + 1 < n; ++i) triangles.push_back({0, i, i + 1});
    return;
  }
  normal.normalize();
  // Orthonormal basis (u, v) with u x v = normal: the polygon is counter-clockwise in it.
  const Eigen::Vector3d u = normal.unitOrthogonal();
  const Eigen::Vector3d v = normal.cross(u);
  std::vector<Eigen::Vector2d> p(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) p[static_cast<std::size_t>(i)] = {points[i].dot(u), points[i].dot(v)};

  std::vector<int> ring(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) ring[static_cast<std::size_t>(i)] = i;
  auto at = [&](int k) { return p[static_cast<std::size_t>(ring[static_cast<std::size_t>(k)])]; };

  while (ring.size() > 3) {
    const int m = static_cast<int>(ring.size());
    int ear = -1;
    int best = 0;  // fallback: the most convex corner
    double best_turn = -std::numeric_limits<double>::infinity();
    for (int k = 0; k < m && ear < 0; ++k) {
      const Eigen::Vector2d a = at((k + m - 1) % m), b = at(k), c = at((k + 1) % m);
      const double turn = cross2(b - a, c - b);
      if (turn > best_turn) {
        best_turn = turn;
        best = k;
      }
      if (turn <= 0.0) continue;  // reflex or flat corner: not an ear
      bool empty = true;
      for (int j = 0; j < m && empty; ++j) {
        if (j == k || j == (k + 1) % m || j == (k + m - 1) % m) continue;
        const Eigen::Vector2d q = at(j);
        if (q == a || q == b || q == c) continue;  // duplicated vertex positions
        empty = !in_triangle(q, a, b, c);
      }
      if (empty) ear = k;
    }
    if (ear < 0) ear = best;
    triangles.push_back({ring[static_cast<std::size_t>((ear + m - 1) % m)], ring[static_cast<std::size_t>(ear)],
                         ring[static_cast<std::size_t>((ear + 1) % m)]});
    ring.erase(ring.begin() + ear);
  }
  triangles.push_back({ring[0], ring[1], ring[2]});
}

}  // namespace g2p::detail
