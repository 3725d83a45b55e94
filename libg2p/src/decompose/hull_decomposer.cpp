// `hull`: one convex hull per part, what engines do with a mesh geom
// themselves. The baseline the other backends are measured against, and the
// fallback of decompose_part().
#include "decompose/backends.h"

namespace g2p {
namespace {

class HullDecomposer : public Decomposer {
 public:
  Status decompose(const Mesh& closed, const DecomposeOptions& options, ConvexDecomposition& out) const override {
    std::vector<Eigen::Vector3d> points;
    points.reserve(closed.positions.size());
    for (const Eigen::Vector3f& p : closed.positions) points.push_back(p.cast<double>());
    Result<Mesh> hull = convex_hull(points, options.max_vertices_per_hull);
    if (!hull.ok()) return hull.status();
    out.hulls.push_back(std::move(*hull));
    return Status::Ok();
  }
};

}  // namespace

std::unique_ptr<Decomposer> make_hull_decomposer() { return std::make_unique<HullDecomposer>(); }

}  // namespace g2p
