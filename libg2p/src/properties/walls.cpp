// measure_walls: rays from the part's patch into its closed volume.
#include <algorithm>
#include <random>

#include "core/segment_tester.h"
#include "g2p/properties.h"

namespace g2p {
namespace {

double median(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Surfaces nearer than this to each other are duplicates (coincident faces
// of a model), not the two sides of a wall.
constexpr double kMinWall = 1e-4;  // metres

}  // namespace

struct SurfaceRays::Impl {
  std::unique_ptr<detail::SegmentTester> tester;
};

SurfaceRays::~SurfaceRays() = default;

Result<std::shared_ptr<const SurfaceRays>> SurfaceRays::build(const Mesh& mesh) {
  Result<std::unique_ptr<detail::SegmentTester>> tester = detail::SegmentTester::create(mesh);
  if (!tester.ok()) return tester.status();
  std::shared_ptr<SurfaceRays> rays(new SurfaceRays());
  rays->impl_ = std::make_unique<Impl>();
  rays->impl_->tester = std::move(*tester);
  rays->num_faces_ = mesh.num_faces();
  return std::shared_ptr<const SurfaceRays>(std::move(rays));
}

Result<WallMeasurement> measure_walls(const Mesh& object, const Part& part, const Mesh& closed, int max_rays,
                                      double surface_tolerance_m) {
  if (part.faces.empty() || closed.num_faces() == 0 || max_rays <= 0) return WallMeasurement{};
  Result<std::shared_ptr<const SurfaceRays>> rays = SurfaceRays::build(object);
  if (!rays.ok()) return rays.status();
  return measure_walls(**rays, object, part, closed, max_rays, surface_tolerance_m);
}

Result<WallMeasurement> measure_walls(const SurfaceRays& object_rays, const Mesh& object, const Part& part,
                                      const Mesh& closed, int max_rays, double surface_tolerance_m) {
  if (part.faces.empty() || closed.num_faces() == 0 || max_rays <= 0) return WallMeasurement{};
  if (object_rays.num_faces() != object.num_faces())
    return Status::InvalidArgument("measure_walls: the rays were built for a mesh of " +
                                   std::to_string(object_rays.num_faces()) + " faces, the object has " +
                                   std::to_string(object.num_faces()));
  const detail::SegmentTester* in_object = object_rays.impl_->tester.get();
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
    // Where the ray along d leaves the closed volume: the first hit on an
    // outward-facing triangle of the closed mesh (hits on inward-facing ones,
    // where the patch sits just outside the closed surface, are stepped over).
    auto exit_along = [&](const Eigen::Vector3d& d) {
      double from = eps;
      for (int step = 0; step < 4; ++step) {
        double hit = 0;
        int tri = -1;
        if (!(*in_closed)->first_hit(p, d, from, 2 * diag, hit, tri)) return -1.0;
        if (face_normal(closed, tri).dot(d) > 0) return hit;
        from = hit + eps;
      }
      return -1.0;
    };
    const double out_minus = exit_along(-n), out_plus = exit_along(n);
    // Inside only if deeper than the closed surface's own tolerance (a grid
    // cell) and than 0.1 mm: coincident duplicate faces are not walls.
    if (out_minus > 0 && out_plus > 0 &&
        std::min(out_minus, out_plus) > std::max({kMinWall, surface_tolerance_m, 1e-3 * (out_minus + out_plus)})) {
      // Inside the closed volume in both directions: the patch here is an
      // inner surface of the part (the inside of a modelled wall); the wall
      // reaches to the nearer side.
      ++w.rays;
      ++w.inner_hits;
      thickness.push_back(out_minus + out_plus);
      inner.push_back(std::min(out_minus, out_plus));
      continue;
    }
    for (const Eigen::Vector3d& d : {Eigen::Vector3d(-n), Eigen::Vector3d(n)}) {
      const double exit_t = d.dot(n) < 0 ? out_minus : out_plus;
      if (!(exit_t > 0)) continue;
      // Skip hits at the start (the patch itself), then look for an inner
      // surface of the object before the ray leaves the volume.
      double hit_t = 0;
      int hit_tri = -1;
      const double skip = std::max({eps, kMinWall, 1e-3 * exit_t});
      ++w.rays;
      thickness.push_back(exit_t);
      if (in_object->first_hit(p, d, skip, 0.9 * exit_t, hit_t, hit_tri)) {
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
