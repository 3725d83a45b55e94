// convex_hull(): Qhull's hull, reduced to a vertex budget by greedy farthest-
// point insertion (each step adds the point farthest outside the hull of the
// points chosen so far, as in the incremental hull of Barber et al. 1996,
// stopped at the budget).
extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include "decompose/hull.h"
#include "g2p/decompose.h"

namespace g2p {
namespace detail {

Status run_qhull(const std::vector<double>& xyz, bool triangulate, QhullHull& out) {
  out = QhullHull{};
  const int n = static_cast<int>(xyz.size() / 3);
  if (n < 4) return Status::InvalidArgument("a convex hull needs at least 4 points (got " + std::to_string(n) + ")");
  // Qhull prints its errors to a FILE; keep them off the user's terminal.
  FILE* quiet = std::fopen("/dev/null", "w");
  qhT qh_storage;
  qhT* qh = &qh_storage;
  qh_zero(qh, quiet);
  std::vector<double> points = xyz;  // Qhull may not write to it, but takes a non-const pointer
  char flags[32];
  std::snprintf(flags, sizeof flags, "qhull%s", triangulate ? " Qt" : "");
  const int code = qh_new_qhull(qh, 3, n, points.data(), False, flags, nullptr, quiet);
  Status status = Status::Ok();
  if (code != 0) {
    status = Status::InvalidArgument("the points span no volume (all on one plane or line)");
  } else {
    std::vector<char> on_hull(static_cast<std::size_t>(n), 0);
    facetT* facet;
    FORALLfacets {
      const Eigen::Vector3d normal(facet->normal[0], facet->normal[1], facet->normal[2]);
      out.planes.emplace_back(normal.x(), normal.y(), normal.z(), facet->offset);
      vertexT* vertex;
      vertexT** vertexp;
      std::vector<int> ids;
      FOREACHvertex_(facet->vertices) {
        const int id = qh_pointid(qh, vertex->point);
        ids.push_back(id);
        if (id >= 0 && id < n) on_hull[static_cast<std::size_t>(id)] = 1;
      }
      if (triangulate && ids.size() == 3) {
        Eigen::Vector3i t(ids[0], ids[1], ids[2]);
        const Eigen::Map<const Eigen::Vector3d> a(&xyz[3 * static_cast<std::size_t>(t[0])]);
        const Eigen::Map<const Eigen::Vector3d> b(&xyz[3 * static_cast<std::size_t>(t[1])]);
        const Eigen::Map<const Eigen::Vector3d> c(&xyz[3 * static_cast<std::size_t>(t[2])]);
        if ((b - a).cross(c - a).dot(normal) < 0) std::swap(t[1], t[2]);
        out.triangles.push_back(t);
      }
    }
    for (int i = 0; i < n; ++i)
      if (on_hull[static_cast<std::size_t>(i)]) out.vertices.push_back(i);
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  if (quiet != nullptr) std::fclose(quiet);
  return status;
}

}  // namespace detail

namespace {

std::vector<double> interleave(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& subset) {
  std::vector<double> xyz;
  xyz.reserve(3 * subset.size());
  for (int i : subset)
    for (int k = 0; k < 3; ++k) xyz.push_back(points[static_cast<std::size_t>(i)][k]);
  return xyz;
}

// Farthest point from a point, line or plane through the chosen ones.
int farthest(const std::vector<Eigen::Vector3d>& p, const std::vector<int>& ids,
             const std::function<double(const Eigen::Vector3d&)>& distance) {
  int best = -1;
  double best_d = -1;
  for (int i : ids) {
    const double d = distance(p[static_cast<std::size_t>(i)]);
    if (d > best_d) best_d = d, best = i;
  }
  return best;
}

}  // namespace

Result<Mesh> convex_hull(const std::vector<Eigen::Vector3d>& points, int max_vertices) {
  return detail::convex_hull_keeping(points, max_vertices, {});
}

Result<Mesh> detail::convex_hull_keeping(const std::vector<Eigen::Vector3d>& points, int max_vertices,
                                         const std::vector<int>& keep) {
  for (const Eigen::Vector3d& p : points)
    if (!p.allFinite()) return Status::InvalidArgument("convex_hull: a point is not finite");
  std::vector<int> all(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) all[i] = static_cast<int>(i);
  detail::QhullHull full;
  G2P_RETURN_IF_ERROR(detail::run_qhull(interleave(points, all), true, full).with_context("convex_hull"));
  std::vector<int> chosen = full.vertices;  // indices into `points`
  for (int& i : chosen) i = all[static_cast<std::size_t>(i)];
  if (max_vertices >= 4 && static_cast<int>(chosen.size()) > max_vertices) {
    // Greedy subset of the full hull's vertices: start from a large
    // tetrahedron, then add the point farthest outside the current hull.
    const std::vector<int> candidates = chosen;
    const auto& P = points;
    std::vector<int> s;
    s.push_back(
        *std::min_element(candidates.begin(), candidates.end(), [&](int a, int b) { return P[a].x() < P[b].x(); }));
    s.push_back(farthest(P, candidates, [&](const Eigen::Vector3d& q) { return (q - P[s[0]]).squaredNorm(); }));
    const Eigen::Vector3d axis = (P[s[1]] - P[s[0]]).normalized();
    s.push_back(farthest(P, candidates, [&](const Eigen::Vector3d& q) {
      const Eigen::Vector3d d = q - P[s[0]];
      return (d - d.dot(axis) * axis).squaredNorm();
    }));
    const Eigen::Vector3d normal = (P[s[1]] - P[s[0]]).cross(P[s[2]] - P[s[0]]).normalized();
    s.push_back(farthest(P, candidates, [&](const Eigen::Vector3d& q) { return std::abs((q - P[s[0]]).dot(normal)); }));
    // The points the caller needs on the hull come next (up to half the
    // budget), when they are vertices of the full hull.
    for (int k : keep) {
      if (static_cast<int>(s.size()) >= std::max(4, max_vertices / 2)) break;
      if (std::find(candidates.begin(), candidates.end(), k) != candidates.end() &&
          std::find(s.begin(), s.end(), k) == s.end())
        s.push_back(k);
    }
    detail::QhullHull current;
    for (;;) {
      if (!detail::run_qhull(interleave(P, s), false, current).ok()) break;  // flat start: keep the full hull
      // Each insertion adds one vertex (and may make older ones interior), so
      // the count reaches the budget exactly.
      if (static_cast<int>(current.vertices.size()) >= max_vertices) break;
      int best = -1;
      double best_d = 0.0;
      for (int c : candidates) {
        double d = -std::numeric_limits<double>::infinity();
        for (const Eigen::Vector4d& pl : current.planes) d = std::max(d, pl.head<3>().dot(P[c]) + pl[3]);
        if (d > best_d) best_d = d, best = c;
      }
      if (best < 0) break;  // every candidate inside: the hull is complete
      s.push_back(best);
    }
    if (static_cast<int>(current.vertices.size()) >= 4) {
      std::vector<int> kept;
      for (int i : current.vertices) kept.push_back(s[static_cast<std::size_t>(i)]);
      chosen = kept;
      G2P_RETURN_IF_ERROR(detail::run_qhull(interleave(P, chosen), true, full).with_context("convex_hull"));
      for (int& i : full.vertices) i = chosen[static_cast<std::size_t>(i)];
      for (Eigen::Vector3i& t : full.triangles)
        for (int k = 0; k < 3; ++k) t[k] = chosen[static_cast<std::size_t>(t[k])];
    }
  }
  // Compact: only the hull's vertices, in input order.
  Mesh mesh;
  std::vector<int> remap(points.size(), -1);
  for (int i : full.vertices) {
    remap[static_cast<std::size_t>(i)] = mesh.num_vertices();
    mesh.positions.push_back(points[static_cast<std::size_t>(i)].cast<float>());
  }
  for (const Eigen::Vector3i& t : full.triangles)
    mesh.triangles.emplace_back(remap[static_cast<std::size_t>(t[0])], remap[static_cast<std::size_t>(t[1])],
                                remap[static_cast<std::size_t>(t[2])]);
  return mesh;
}

}  // namespace g2p
