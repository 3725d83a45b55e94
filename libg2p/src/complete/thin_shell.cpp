// thin_part_shell: a part too thin for the completer's grid, closed as a
// shell of its measured thickness (#50). A board given as its top and bottom
// faces (two parts, no edge between them) is 2 mm thick; on a grid of 4 mm
// cells the partition closes both faces into one slab of about a cell, and
// the parts hold 599 cm^3 for the board's 360. The input says the thickness
// exactly: a ray from each vertex inward meets the surface behind it. Each
// part takes half of that distance, the same halfway split that
// estimate_volumes uses, so two such parts meet at the board's middle.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "complete/closed_parts.h"
#include "core/segment_tester.h"
#include "g2p/complete.h"

namespace g2p {
namespace {

// Per face, the index of its edge-connected piece (faces sharing an edge,
// either way round, are in one piece).
std::vector<int> edge_connected_pieces(const Mesh& m) {
  const int nf = m.num_faces();
  auto key = [](int a, int b) {
    return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
  };
  std::unordered_map<std::uint64_t, std::vector<int>> faces_of_edge;
  for (int f = 0; f < nf; ++f)
    for (int e = 0; e < 3; ++e)
      faces_of_edge[key(m.triangles[static_cast<std::size_t>(f)][e],
                        m.triangles[static_cast<std::size_t>(f)][(e + 1) % 3])]
          .push_back(f);
  std::vector<int> piece(static_cast<std::size_t>(nf), -1);
  std::vector<int> stack;
  int pieces = 0;
  for (int seed = 0; seed < nf; ++seed) {
    if (piece[static_cast<std::size_t>(seed)] >= 0) continue;
    piece[static_cast<std::size_t>(seed)] = pieces;
    stack.push_back(seed);
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      for (int e = 0; e < 3; ++e)
        for (int g : faces_of_edge[key(m.triangles[static_cast<std::size_t>(f)][e],
                                       m.triangles[static_cast<std::size_t>(f)][(e + 1) % 3])])
          if (piece[static_cast<std::size_t>(g)] < 0) {
            piece[static_cast<std::size_t>(g)] = pieces;
            stack.push_back(g);
          }
    }
    ++pieces;
  }
  return piece;
}

}  // namespace

Mesh thin_part_shell(const Mesh& mesh, const std::vector<Part>& parts, std::size_t part, double weld_tolerance) {
  if (part >= parts.size()) return {};
  std::vector<int> source;  // the object's face of every patch face
  const Mesh patch = detail::welded_part_faces(mesh, parts[part], detail::weld_distance(mesh, weld_tolerance), &source);
  const int nv = patch.num_vertices(), nf = patch.num_faces();
  if (nf == 0) return {};

  // Where a ray lands: each face of the object tagged by its part, and the
  // part's own faces by their edge-connected piece of the patch (-2 - piece),
  // so that the top and bottom faces of a board, one part with no edge
  // between them, each take half the interval as two parts would.
  std::vector<int> landing(static_cast<std::size_t>(mesh.num_faces()), -1);
  for (std::size_t p = 0; p < parts.size(); ++p)
    for (int f : parts[p].faces)
      if (f >= 0 && f < mesh.num_faces()) landing[static_cast<std::size_t>(f)] = static_cast<int>(p);
  const std::vector<int> piece = edge_connected_pieces(patch);
  for (int f = 0; f < nf; ++f)
    landing[static_cast<std::size_t>(source[static_cast<std::size_t>(f)])] = -2 - piece[static_cast<std::size_t>(f)];
  std::vector<int> vertex_piece(static_cast<std::size_t>(nv), 0);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      vertex_piece[static_cast<std::size_t>(patch.triangles[static_cast<std::size_t>(f)][k])] =
          piece[static_cast<std::size_t>(f)];

  // Area-weighted vertex normals of the patch (outward, as the input's faces).
  std::vector<Eigen::Vector3d> normal(static_cast<std::size_t>(nv), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& t : patch.triangles) {
    const Eigen::Vector3d a = patch.positions[static_cast<std::size_t>(t[0])].cast<double>();
    const Eigen::Vector3d n = (patch.positions[static_cast<std::size_t>(t[1])].cast<double>() - a)
                                  .cross(patch.positions[static_cast<std::size_t>(t[2])].cast<double>() - a);
    for (int k = 0; k < 3; ++k) normal[static_cast<std::size_t>(t[k])] += n;
  }
  Eigen::Vector3d extent = bounds(patch).sizes();
  std::sort(extent.data(), extent.data() + 3);
  const double deepest = 0.1 * extent[1];  // a shell this deep is no longer thin
  const double diagonal = bounds(mesh).diagonal().norm();
  if (!(deepest > 0) || !(diagonal > 0)) return {};

  Result<std::unique_ptr<detail::SegmentTester>> rays = detail::SegmentTester::create(mesh);
  if (!rays.ok()) return {};
  Mesh shell;
  shell.positions = patch.positions;
  shell.positions.resize(static_cast<std::size_t>(2 * nv));
  for (int v = 0; v < nv; ++v) {
    const double length = normal[static_cast<std::size_t>(v)].norm();
    if (!(length > 0)) return {};
    const Eigen::Vector3d n = normal[static_cast<std::size_t>(v)] / length;
    const Eigen::Vector3d p = patch.positions[static_cast<std::size_t>(v)].cast<double>();
    double t = 0.0;
    int hit = -1;
    // Past the faces around the vertex itself, at most twice the thinness bound.
    if (!(*rays)->first_hit(p, -n, 1e-6 * diagonal, 2.0 * deepest, t, hit)) return {};
    const int other = landing[static_cast<std::size_t>(hit)];
    // Another part's faces, or another piece of this part's: a split interval.
    if (other == -1 || other == -2 - vertex_piece[static_cast<std::size_t>(v)]) return {};
    // The face behind must be met from inside (its normal along the ray).
    const Eigen::Vector3i& h = mesh.triangles[static_cast<std::size_t>(hit)];
    const Eigen::Vector3d a = mesh.positions[static_cast<std::size_t>(h[0])].cast<double>();
    const Eigen::Vector3d face_normal = (mesh.positions[static_cast<std::size_t>(h[1])].cast<double>() - a)
                                            .cross(mesh.positions[static_cast<std::size_t>(h[2])].cast<double>() - a);
    if (!(face_normal.dot(-n) > 0)) return {};
    if (0.5 * t > deepest) return {};
    shell.positions[static_cast<std::size_t>(nv + v)] = (p - 0.5 * t * n).cast<float>();
  }

  // The faces, the inner copy turned inward, and a wall along every open edge.
  shell.triangles = patch.triangles;
  for (const Eigen::Vector3i& t : patch.triangles) shell.triangles.emplace_back(nv + t[0], nv + t[2], nv + t[1]);
  auto key = [](int a, int b) { return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b); };
  std::unordered_map<std::uint64_t, int> directed;
  directed.reserve(static_cast<std::size_t>(3 * nf));
  for (const Eigen::Vector3i& t : patch.triangles)
    for (int e = 0; e < 3; ++e) ++directed[key(t[e], t[(e + 1) % 3])];
  for (const Eigen::Vector3i& t : patch.triangles)
    for (int e = 0; e < 3; ++e) {
      const int a = t[e], b = t[(e + 1) % 3];
      if (directed[key(a, b)] != 1) return {};  // an edge used twice the same way: not an oriented surface
      auto reverse = directed.find(key(b, a));
      if (reverse != directed.end() && reverse->second > 0) continue;  // an inner edge
      shell.triangles.emplace_back(b, a, nv + a);
      shell.triangles.emplace_back(b, nv + a, nv + b);
    }
  if (!check_closed_mesh(shell).watertight()) return {};
  return shell;
}

}  // namespace g2p
