// `hacd`: hierarchical approximate convex decomposition (Mamou and Ghorbel,
// "A simple and efficient approach for 3D mesh approximate convex
// decomposition", ICIP 2009) through the HACD library Debian ships with
// Bullet's extras (libbullet-extras-dev). Built only when that library is
// found (G2P_WITH_HACD); measured against `voxel-cut` in docs/decompose.md.
//
// HACD clusters the triangles of the surface by merging neighbours while the
// merged cluster's concavity stays under a bound, so its cost grows with the
// triangle count: the closed volume is first simplified to about `triangles`
// triangles (quadric edge collapse). HACD's cluster count is a minimum, not a
// maximum, so the concavity bound is doubled until the clusters fit the hull
// budget.
#include <hacdHACD.h>

#include <algorithm>
#include <cmath>

#include "core/settings.h"
#include "core/simplify.h"
#include "decompose/backends.h"

namespace g2p {
namespace {

class HacdDecomposer : public Decomposer {
 public:
  SettingsSpec settings() override {
    return SettingsSpec("hacd")
        .number("concavity", concavity_, Range::above(0), "",
                "HACD's bound on a cluster's concavity, in its normalised units")
        .integer("triangles", triangles_, 100, 1000000, "",
                 "the closed volume is simplified to about this many triangles first");
  }

  Status decompose(const Mesh& closed, const DecomposeOptions& options, ConvexDecomposition& out) const override {
    Mesh mesh = closed;
    const double diagonal = bounds(mesh).diagonal().norm();
    for (double error = 1e-3 * diagonal; mesh.num_faces() > triangles_ && error < 0.1 * diagonal; error *= 2)
      detail::simplify_closed_mesh(mesh, error);
    if (mesh.num_faces() != closed.num_faces())
      out.notes.push_back("hacd: simplified from " + std::to_string(closed.num_faces()) + " to " +
                          std::to_string(mesh.num_faces()) + " triangles first");
    std::vector<HACD::Vec3<HACD::Real>> points;
    std::vector<HACD::Vec3<long>> triangles;
    for (const Eigen::Vector3f& p : mesh.positions) points.emplace_back(p.x(), p.y(), p.z());
    for (const Eigen::Vector3i& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
    double concavity = concavity_;
    for (int attempt = 0; attempt < 8; ++attempt, concavity *= 2) {
      std::vector<HACD::Vec3<HACD::Real>> work = points;  // HACD normalises its input in place
      HACD::HACD hacd;
      hacd.SetPoints(work.data());
      hacd.SetNPoints(work.size());
      hacd.SetTriangles(triangles.data());
      hacd.SetNTriangles(triangles.size());
      hacd.SetCompacityWeight(0.0001);  // the library's example values
      hacd.SetVolumeWeight(0.0);
      hacd.SetScaleFactor(1000.0);
      hacd.SetConnectDist(30.0);
      hacd.SetNClusters(1);
      hacd.SetNVerticesPerCH(static_cast<std::size_t>(options.max_vertices_per_hull));
      hacd.SetConcavity(concavity);
      hacd.SetAddExtraDistPoints(true);
      hacd.SetAddFacesPoints(true);
      hacd.SetAddNeighboursDistPoints(false);
      if (!hacd.Compute()) return Status::Internal("hacd: the library's Compute() failed");
      const std::size_t n = hacd.GetNClusters();
      if (n > static_cast<std::size_t>(options.max_hulls)) continue;
      for (std::size_t c = 0; c < n; ++c) {
        std::vector<HACD::Vec3<HACD::Real>> ch(hacd.GetNPointsCH(c));
        std::vector<HACD::Vec3<long>> ct(hacd.GetNTrianglesCH(c));
        if (ch.empty() || !hacd.GetCH(c, ch.data(), ct.data())) continue;
        std::vector<Eigen::Vector3d> hull_points;
        for (const auto& q : ch) hull_points.emplace_back(q.X(), q.Y(), q.Z());
        Result<Mesh> hull = convex_hull(hull_points, options.max_vertices_per_hull);
        if (hull.ok()) out.hulls.push_back(std::move(*hull));
      }
      if (attempt > 0)
        out.notes.push_back("hacd: concavity raised to " + std::to_string(concavity) + " to fit --max-hulls");
      return Status::Ok();
    }
    return Status::InvalidArgument("hacd: more clusters than --max-hulls at every concavity tried");
  }

 private:
  double concavity_ = 100.0;  // HACD's bound on a cluster's concavity, in its normalised units (the example's)
  int triangles_ = 2000;      // simplify the closed volume to about this many triangles first
};

}  // namespace

std::unique_ptr<Decomposer> make_hacd_decomposer() { return std::make_unique<HacdDecomposer>(); }

}  // namespace g2p
