// Face adjacency over welded vertices.
//
// Welding: vertices within `tolerance` (relative to the bounding-box diagonal)
// of an earlier vertex take that vertex as their representative. A grid of
// cells of twice the tolerance holds the representatives; a vertex at
// fractional cell position f can only have a partner within the tolerance in
// its own cell or in the neighbour cell on the side f is nearer to, so 8 cells
// are searched, not 27.
//
// Adjacency: every edge between two distinct welded vertices is keyed by its
// endpoints and the keys sorted; faces with the same key share that edge
// (non-manifold edges link every pair of their faces).
#include <algorithm>
#include <cmath>

#include <tbb/parallel_sort.h>

#include "core/cell_index.h"
#include "g2p/project.h"

namespace g2p {

Result<FaceGraph> build_face_graph(const Mesh& mesh, double weld_tolerance) {
  G2P_RETURN_IF_ERROR(validate(mesh).with_context("face graph"));
  if (!(weld_tolerance >= 0.0) || weld_tolerance > 0.1)
    return Status::InvalidArgument("face graph: weld tolerance must lie in [0, 0.1] of the object's size");
  FaceGraph g;
  const std::size_t nv = mesh.positions.size(), nf = mesh.triangles.size();
  g.welded_vertex.resize(nv);

  const Eigen::AlignedBox3d box = bounds(mesh);
  const double eps = weld_tolerance * (nv > 0 ? box.diagonal().norm() : 0.0);
  if (eps <= 0.0) {
    for (std::size_t v = 0; v < nv; ++v) g.welded_vertex[v] = static_cast<int>(v);
  } else {
    const double cell = 2.0 * eps;
    const Eigen::Vector3d origin = box.min();
    auto key = &detail::CellIndex::key;
    detail::CellIndex head(nv);     // cell -> first representative in it
    std::vector<int> next(nv, -1);  // chain of representatives in a cell
    for (std::size_t v = 0; v < nv; ++v) {
      const Eigen::Vector3d p = (mesh.positions[v].cast<double>() - origin) / cell;
      const Eigen::Vector3d fl = p.array().floor();
      const std::int64_t c[3] = {static_cast<std::int64_t>(fl.x()), static_cast<std::int64_t>(fl.y()),
                                 static_cast<std::int64_t>(fl.z())};
      const int dir[3] = {p.x() - fl.x() < 0.5 ? -1 : 1, p.y() - fl.y() < 0.5 ? -1 : 1, p.z() - fl.z() < 0.5 ? -1 : 1};
      int rep = -1;
      for (int i = 0; i < 8 && rep < 0; ++i) {
        const int* first =
            head.find(key(c[0] + ((i & 1) ? dir[0] : 0), c[1] + ((i & 2) ? dir[1] : 0), c[2] + ((i & 4) ? dir[2] : 0)));
        if (first == nullptr) continue;
        for (int r = *first; r >= 0; r = next[static_cast<std::size_t>(r)]) {
          if ((mesh.positions[static_cast<std::size_t>(r)] - mesh.positions[v]).cast<double>().norm() <= eps) {
            rep = r;
            break;
          }
        }
      }
      if (rep >= 0) {
        g.welded_vertex[v] = rep;
        continue;
      }
      g.welded_vertex[v] = static_cast<int>(v);
      int& first = head.at(key(c[0], c[1], c[2]), -1);
      next[v] = first;
      first = static_cast<int>(v);
    }
  }

  struct EdgeRef {
    std::uint64_t key;
    int face;
  };
  std::vector<EdgeRef> edges;
  edges.reserve(3 * nf);
  for (std::size_t f = 0; f < nf; ++f) {
    const Eigen::Vector3i& t = mesh.triangles[f];
    for (int k = 0; k < 3; ++k) {
      const int a = g.welded_vertex[static_cast<std::size_t>(t[k])];
      const int b = g.welded_vertex[static_cast<std::size_t>(t[(k + 1) % 3])];
      if (a == b) continue;
      const auto lo = static_cast<std::uint64_t>(std::min(a, b)), hi = static_cast<std::uint64_t>(std::max(a, b));
      edges.push_back({(lo << 32) | hi, static_cast<int>(f)});
    }
  }
  // Elements that compare equal are equal (same key, same face): the parallel
  // sort gives what std::sort gives.
  tbb::parallel_sort(edges.begin(), edges.end(), [](const EdgeRef& x, const EdgeRef& y) {
    return x.key != y.key ? x.key < y.key : x.face < y.face;
  });

  // Count, then fill, the neighbour lists (compressed rows).
  std::vector<int> degree(nf, 0);
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    for (std::size_t a = i; a < j; ++a)
      for (std::size_t b = i; b < j; ++b)
        if (a != b && edges[a].face != edges[b].face) ++degree[static_cast<std::size_t>(edges[a].face)];
    i = j;
  }
  g.offsets.assign(nf + 1, 0);
  for (std::size_t f = 0; f < nf; ++f) g.offsets[f + 1] = g.offsets[f] + degree[f];
  g.neighbors.resize(static_cast<std::size_t>(g.offsets[nf]));
  g.shared_edge_m.resize(g.neighbors.size());
  std::vector<int> fill(g.offsets.begin(), g.offsets.end() - 1);
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    const auto a_vertex = static_cast<std::size_t>(edges[i].key >> 32);
    const auto b_vertex = static_cast<std::size_t>(edges[i].key & 0xFFFFFFFFu);
    const float length = (mesh.positions[a_vertex] - mesh.positions[b_vertex]).norm();
    for (std::size_t a = i; a < j; ++a) {
      for (std::size_t b = i; b < j; ++b) {
        if (a == b || edges[a].face == edges[b].face) continue;
        const int slot = fill[static_cast<std::size_t>(edges[a].face)]++;
        g.neighbors[static_cast<std::size_t>(slot)] = edges[b].face;
        g.shared_edge_m[static_cast<std::size_t>(slot)] = length;
      }
    }
    i = j;
  }
  return g;
}

}  // namespace g2p
