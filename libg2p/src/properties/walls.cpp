// measure_walls: rays from the part's patch into its closed volume.
#include <algorithm>
#include <random>

#include "complete/segment_tester.h"
#include "g2p/properties.h"

namespace g2p {
namespace {

double median(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

Result<WallMeasurement> measure_walls(const Mesh& object, const Part& part, const Mesh& closed, int max_rays) {
  if (part.faces.empty() || closed.num_faces() == 0 || max_rays <= 0) return WallMeasurement{};
  Result<std::unique_ptr<detail::SegmentTester>> in_object = detail::SegmentTester::create(object);
  if (!in_object.ok()) return in_object.status();
  Result<std::unique_ptr<detail::SegmentTester>> in_closed = detail::SegmentTester::create(closed);
  if (!in_closed.ok()) return in_closed.status();

  // Area-weighted, deterministic sample of the part's faces.
  std::vector<double> cumulative;
  cumulative.reserve(part.faces.size());
  double total = 0.0;
  for (int f : part.faces) cumulative.push_back(total += face_area(object, f));
  if (!(total > 0)) return WallMeasurement{};
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double diag = bounds(closed).diagonal().norm();
  const double eps = 1e-6 * diag;

  WallMeasurement w;
  std::vector<double> thickness, inner;
  for (int r = 0; r < max_rays; ++r) {
    const std::size_t k = static_cast<std::size_t>(
        std::lower_bound(cumulative.begin(), cumulative.end(), u(rng) * total) - cumulative.begin());
    const int f = part.faces[std::min(k, part.faces.size() - 1)];
    const Eigen::Vector3i& t = object.triangles[static_cast<std::size_t>(f)];
    double a = u(rng), b = u(rng);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    const Eigen::Vector3d p0 = object.positions[static_cast<std::size_t>(t[0])].cast<double>();
    const Eigen::Vector3d p = p0 + a * (object.positions[static_cast<std::size_t>(t[1])].cast<double>() - p0) +
                              b * (object.positions[static_cast<std::size_t>(t[2])].cast<double>() - p0);
    const Eigen::Vector3d n = face_normal(object, f);
    if (n.isZero()) continue;
    // Into the closed volume: the direction along which the ray leaves it
    // through an outward-facing triangle of the closed mesh (the patch may be
    // wound either way).
    for (const Eigen::Vector3d& d : {Eigen::Vector3d(-n), Eigen::Vector3d(n)}) {
      double exit_t = 0;
      int exit_tri = -1;
      if (!(*in_closed)->first_hit(p, d, eps, 2 * diag, exit_t, exit_tri)) continue;
      if (face_normal(closed, exit_tri).dot(d) <= 0) continue;  // entering, so p was outside along d
      // The patch itself may sit a little inside the closed surface; skip
      // hits at the start, then look for an inner surface of the object.
      double hit_t = 0;
      int hit_tri = -1;
      const double skip = std::max(eps, 1e-3 * exit_t);
      ++w.rays;
      thickness.push_back(exit_t);
      if ((*in_object)->first_hit(p, d, skip, 0.9 * exit_t, hit_t, hit_tri)) {
        ++w.inner_hits;
        inner.push_back(hit_t);
      }
      break;
    }
  }
  w.thickness_m = median(thickness);
  w.inner_wall_m = median(inner);
  return w;
}

}  // namespace g2p
