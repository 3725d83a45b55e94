// How far a part's surface lies outside the union of its convex hulls:
// stratified area samples, each tested against the hulls nearest first (box
// distance, then the face planes) and measured exactly against the nearest.
#include "decompose/coverage.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace g2p::detail {
namespace {

// The closest point of triangle abc to p (Ericson, Real-Time Collision
// Detection, 5.1.5), returned as the squared distance.
double squared_distance_to_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.squaredNorm();
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.squaredNorm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (ap - (d1 / (d1 - d3)) * ab).squaredNorm();
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.squaredNorm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (ap - (d2 / (d2 - d6)) * ac).squaredNorm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return (bp - ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b)).squaredNorm();
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return (ap - ab * v - ac * w).squaredNorm();
}

// A hull prepared for many queries: its box and face planes.
struct PreparedHull {
  const Mesh* mesh = nullptr;
  Eigen::AlignedBox3d box;
  std::vector<Eigen::Vector4d> planes;  // n . p + offset > 0 outside; n unit length
  std::vector<int> faces;               // the face of each plane

  // A lower bound of the distance to the hull: the largest plane distance
  // (0 or less inside), and the plane that gives it.
  double plane_bound(const Eigen::Vector3d& p, std::size_t& which) const {
    double worst = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < planes.size(); ++i) {
      const double d = planes[i].head<3>().dot(p) + planes[i][3];
      if (d > worst) worst = d, which = i;
    }
    return worst;
  }

  // The bound is the distance itself when p's foot on that plane lies in
  // its face (the nearest point of the hull is then on that face).
  bool foot_in_face(const Eigen::Vector3d& p, std::size_t plane, double bound) const {
    const Eigen::Vector3d foot = p - bound * planes[plane].head<3>();
    const Eigen::Vector3i& t = mesh->triangles[static_cast<std::size_t>(faces[plane])];
    const Eigen::Vector3d a = mesh->positions[static_cast<std::size_t>(t[0])].cast<double>();
    const Eigen::Vector3d b = mesh->positions[static_cast<std::size_t>(t[1])].cast<double>();
    const Eigen::Vector3d c = mesh->positions[static_cast<std::size_t>(t[2])].cast<double>();
    const Eigen::Vector3d n = planes[plane].head<3>();
    return n.dot((b - a).cross(foot - a)) >= 0 && n.dot((c - b).cross(foot - b)) >= 0 &&
           n.dot((a - c).cross(foot - c)) >= 0;
  }
};

PreparedHull prepare(const Mesh& hull) {
  PreparedHull h;
  h.mesh = &hull;
  h.box = bounds(hull);
  for (int f = 0; f < hull.num_faces(); ++f) {
    const Eigen::Vector3i& t = hull.triangles[static_cast<std::size_t>(f)];
    const Eigen::Vector3d a = hull.positions[static_cast<std::size_t>(t[0])].cast<double>();
    const Eigen::Vector3d b = hull.positions[static_cast<std::size_t>(t[1])].cast<double>();
    const Eigen::Vector3d c = hull.positions[static_cast<std::size_t>(t[2])].cast<double>();
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double length = n.norm();
    if (!(length > 0)) continue;  // a degenerate face bounds nothing
    h.planes.emplace_back(n.x() / length, n.y() / length, n.z() / length, -n.dot(a) / length);
    h.faces.push_back(f);
  }
  return h;
}

double exact_distance(const Eigen::Vector3d& p, const Mesh& hull) {
  double best = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3i& t : hull.triangles)
    best = std::min(best, squared_distance_to_triangle(p, hull.positions[static_cast<std::size_t>(t[0])].cast<double>(),
                                                       hull.positions[static_cast<std::size_t>(t[1])].cast<double>(),
                                                       hull.positions[static_cast<std::size_t>(t[2])].cast<double>()));
  return std::sqrt(best);
}

// The distance from p to the union of the hulls. `order` is scratch space.
double distance_to_union(const Eigen::Vector3d& p, const std::vector<PreparedHull>& hulls,
                         std::vector<std::pair<double, std::size_t>>& order) {
  // Points on a hull's surface (the hulls are made from the part's surface)
  // count as inside: a micrometre's rounding is no uncovered surface.
  constexpr double kOnSurface = 1e-6;
  order.clear();
  for (std::size_t i = 0; i < hulls.size(); ++i) order.emplace_back(hulls[i].box.exteriorDistance(p), i);
  std::sort(order.begin(), order.end());
  double best = std::numeric_limits<double>::infinity();
  for (const auto& [box_distance, i] : order) {
    if (box_distance >= best) break;  // the boxes are sorted: no farther hull can be nearer
    std::size_t plane = 0;
    const double bound = hulls[i].plane_bound(p, plane);
    if (bound <= kOnSurface) return 0.0;
    if (bound >= best) continue;
    best = std::min(best, hulls[i].foot_in_face(p, plane, bound) ? bound : exact_distance(p, *hulls[i].mesh));
  }
  return std::isfinite(best) ? best : 0.0;
}

}  // namespace

double distance_to_convex(const Eigen::Vector3d& p, const Mesh& hull) {
  const PreparedHull h = prepare(hull);
  if (h.planes.empty()) return 0.0;
  std::size_t plane = 0;
  const double bound = h.plane_bound(p, plane);
  if (bound <= 0) return 0.0;
  return h.foot_in_face(p, plane, bound) ? bound : exact_distance(p, hull);
}

Uncovered uncovered_distance(const Mesh& closed, const std::vector<Mesh>& hulls, int samples) {
  Uncovered out;
  if (hulls.empty() || closed.num_faces() == 0 || samples < 1) return out;
  std::vector<PreparedHull> prepared;
  for (const Mesh& h : hulls) prepared.push_back(prepare(h));
  std::vector<std::pair<double, std::size_t>> order;
  const double total = surface_area(closed);
  if (!(total > 0)) return out;
  // Face f gets the samples whose stratum centre (k + 0.5) / samples of the
  // running area falls in its share; within the face, points of the R2
  // low-discrepancy sequence folded into the triangle.
  double running = 0.0, sum = 0.0;
  long taken = 0, next = 0;
  constexpr double kG1 = 0.7548776662466927, kG2 = 0.5698402909980532;  // R2 (Roberts 2018)
  for (int f = 0; f < closed.num_faces(); ++f) {
    running += face_area(closed, f);
    const long end = std::min<long>(samples, static_cast<long>(std::floor(running / total * samples + 0.5)));
    if (end <= next) continue;
    const Eigen::Vector3i& t = closed.triangles[static_cast<std::size_t>(f)];
    const Eigen::Vector3d a = closed.positions[static_cast<std::size_t>(t[0])].cast<double>();
    const Eigen::Vector3d b = closed.positions[static_cast<std::size_t>(t[1])].cast<double>();
    const Eigen::Vector3d c = closed.positions[static_cast<std::size_t>(t[2])].cast<double>();
    for (long k = next; k < end; ++k) {
      double u = std::fmod(0.5 + kG1 * static_cast<double>(k), 1.0),
             v = std::fmod(0.5 + kG2 * static_cast<double>(k), 1.0);
      if (u + v > 1) u = 1 - u, v = 1 - v;
      const double d = distance_to_union(a + u * (b - a) + v * (c - a), prepared, order);
      sum += d;
      out.max_m = std::max(out.max_m, d);
      ++taken;
    }
    next = end;
  }
  if (taken > 0) out.mean_m = sum / static_cast<double>(taken);
  if (closed.num_vertices() <= samples)
    for (const Eigen::Vector3f& p : closed.positions)
      out.max_m = std::max(out.max_m, distance_to_union(p.cast<double>(), prepared, order));
  return out;
}

}  // namespace g2p::detail
