// check_closed_mesh: the validation every completed part goes through.
#include <algorithm>
#include <cstdint>
#include <numeric>

#include <tbb/parallel_sort.h>

#include "complete/geometry.h"
#include "core/union_find.h"
#include "g2p/complete.h"

namespace g2p {

namespace {

constexpr int kNoOpposite = -1;   // a boundary edge
constexpr int kBadOpposite = -2;  // more than two faces on the edge, or two wound the same way

// The half-edges of every face, h = 3 f + e running from corner e to corner
// e + 1, each paired with the half-edge running the other way along the same
// edge. One sort by undirected edge, then linear passes: the checks below
// look a neighbour up in O(1) rather than by a search per step.
std::vector<int> opposite_half_edges(const Mesh& mesh) {
  const std::size_t nh = static_cast<std::size_t>(mesh.num_faces()) * 3;
  std::vector<std::pair<std::uint64_t, int>> edges(nh);  // (low vertex << 32 | high vertex, half-edge)
  for (std::size_t h = 0; h < nh; ++h) {
    const Eigen::Vector3i& t = mesh.triangles[h / 3];
    const int e = static_cast<int>(h % 3);
    const auto from = static_cast<std::uint32_t>(t[e]), to = static_cast<std::uint32_t>(t[(e + 1) % 3]);
    const std::uint64_t key = (static_cast<std::uint64_t>(std::min(from, to)) << 32) | std::max(from, to);
    edges[h] = {key, static_cast<int>(h)};
  }
  tbb::parallel_sort(edges.begin(), edges.end());  // a total order: the same result as std::sort
  auto forward = [&](int h) {                      // runs from the lower vertex index to the higher
    const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(h / 3)];
    return t[h % 3] < t[(h % 3 + 1) % 3];
  };
  std::vector<int> opposite(nh, kNoOpposite);
  for (std::size_t i = 0; i < nh;) {
    std::size_t j = i + 1;
    while (j < nh && edges[j].first == edges[i].first) ++j;
    if (j - i == 2 && forward(edges[i].second) != forward(edges[i + 1].second)) {
      opposite[static_cast<std::size_t>(edges[i].second)] = edges[i + 1].second;
      opposite[static_cast<std::size_t>(edges[i + 1].second)] = edges[i].second;
    } else if (j - i > 1) {
      for (std::size_t k = i; k < j; ++k) opposite[static_cast<std::size_t>(edges[k].second)] = kBadOpposite;
    }
    i = j;
  }
  return opposite;
}

// Whether every edge has exactly two faces, wound in opposite directions;
// counts the edge-connected pieces (over the edges that do) in `num_components`.
bool closed_and_oriented(int nf, const std::vector<int>& opposite, int& num_components) {
  bool closed = true;
  detail::UnionFind sets(static_cast<std::size_t>(nf));
  for (std::size_t h = 0; h < opposite.size(); ++h) {
    const int g = opposite[h];
    if (g < 0) {
      closed = false;
      continue;
    }
    sets.unite(static_cast<int>(h / 3), g / 3);
  }
  for (int f = 0; f < nf; ++f) num_components += sets.find(f) == f;
  return closed;
}

// Vertex manifoldness of a closed mesh: walking across edges around each
// vertex visits all of its triangles in one cycle.
bool vertex_manifold(const Mesh& mesh, const std::vector<int>& opposite) {
  std::vector<int> incident(mesh.positions.size(), 0);
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) ++incident[static_cast<std::size_t>(t[e])];
  std::vector<char> done(mesh.positions.size(), 0);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3i& t0 = mesh.triangles[static_cast<std::size_t>(f)];
    for (int corner = 0; corner < 3; ++corner) {
      const int v = t0[corner];
      if (done[static_cast<std::size_t>(v)]) continue;
      done[static_cast<std::size_t>(v)] = 1;
      int face = f, steps = 0;
      do {
        const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(face)];
        const int k = t[0] == v ? 0 : t[1] == v ? 1 : 2;
        // The neighbour across the edge from v to the next corner.
        const int across = opposite[static_cast<std::size_t>(3 * face + k)];
        face = across < 0 ? -1 : across / 3;
        ++steps;
      } while (face >= 0 && face != f && steps <= incident[static_cast<std::size_t>(v)]);
      if (face != f || steps != incident[static_cast<std::size_t>(v)]) return false;
    }
  }
  return true;
}

// Enclosed volume (divergence theorem, about the centroid for precision).
double enclosed_volume(const Mesh& mesh) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : mesh.positions) centre += p.cast<double>();
  centre /= static_cast<double>(std::max<std::size_t>(1, mesh.positions.size()));
  double six_v = 0.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[static_cast<std::size_t>(t[0])].cast<double>() - centre;
    const Eigen::Vector3d b = mesh.positions[static_cast<std::size_t>(t[1])].cast<double>() - centre;
    const Eigen::Vector3d d = mesh.positions[static_cast<std::size_t>(t[2])].cast<double>() - centre;
    six_v += a.dot(b.cross(d));
  }
  return six_v / 6.0;
}

// The largest distance from a vertex of `mesh` to `patch`. Only distances
// above the running maximum matter: each search stops at the first triangle
// closer than that. Large meshes are sampled: at most `max_samples` vertices,
// evenly spread over the vertex order.
double max_distance_to_patch(const Mesh& mesh, const Mesh& patch, int max_samples) {
  const detail::TriangleBins bins(patch);
  double worst = 0.0;
  const std::size_t n = mesh.positions.size();
  const std::size_t step = std::max<std::size_t>(1, n / static_cast<std::size_t>(std::max(1, max_samples)));
  for (std::size_t v = 0; v < n; v += step)
    worst = std::max(worst, bins.distance(mesh.positions[v].cast<double>(), worst));
  return worst;
}

}  // namespace

bool MeshChecks::watertight() const {
  return closed && manifold && outward && volume_m3 > 0 && (!self_intersections_checked || self_intersection_free);
}

MeshChecks check_closed_mesh(const Mesh& mesh, const Mesh* patch, const MeshCheckOptions& options) {
  MeshChecks c;
  const int nf = mesh.num_faces();
  if (nf == 0 || !validate(mesh).ok()) return c;
  c.area_m2 = surface_area(mesh);

  const std::vector<int> opposite = opposite_half_edges(mesh);
  c.closed = closed_and_oriented(nf, opposite, c.num_components);
  if (c.closed) c.manifold = vertex_manifold(mesh, opposite);

  c.volume_m3 = enclosed_volume(mesh);
  const double diagonal = bounds(mesh).diagonal().norm();
  c.outward = c.closed && c.volume_m3 > 1e-12 * diagonal * diagonal * diagonal;

  if (nf <= options.max_faces_for_intersections) {
    const detail::TriangleBins bins(mesh);
    const auto pairs = bins.intersecting_pairs(1000);
    c.self_intersections_checked = true;
    c.num_self_intersections = static_cast<int>(pairs.size());
    c.self_intersection_free = pairs.empty();
  }

  if (patch != nullptr && patch->num_faces() > 0) {
    c.max_distance_m = max_distance_to_patch(mesh, *patch, options.max_distance_samples);
    const double diag = bounds(*patch).diagonal().norm();
    c.relative_distance = diag > 0 ? c.max_distance_m / diag : 0.0;
  }
  return c;
}

Mesh part_patch(const Mesh& mesh, const Part& part) {
  Mesh out;
  std::vector<int> remap(mesh.positions.size(), -1);
  for (int f : part.faces) {
    if (f < 0 || f >= mesh.num_faces()) continue;
    Eigen::Vector3i t = mesh.triangles[static_cast<std::size_t>(f)];
    for (int e = 0; e < 3; ++e) {
      int& r = remap[static_cast<std::size_t>(t[e])];
      if (r < 0) {
        r = out.num_vertices();
        out.positions.push_back(mesh.positions[static_cast<std::size_t>(t[e])]);
      }
      t[e] = r;
    }
    out.triangles.push_back(t);
    if (!mesh.face_source.empty()) out.face_source.push_back(mesh.face_source[static_cast<std::size_t>(f)]);
  }
  return out;
}

}  // namespace g2p
