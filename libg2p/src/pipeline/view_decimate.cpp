#include "pipeline/view_decimate.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/cell_index.h"

namespace g2p::detail {
namespace {

// The faces as they are, with only the vertices they use.
ViewMesh extract(const Mesh& mesh, const std::vector<int>& faces) {
  ViewMesh out;
  std::vector<int> index(mesh.positions.size(), -1);  // each vertex's in `out`, -1 before it is met
  out.mesh.triangles.reserve(faces.size());
  out.source_face.reserve(faces.size());
  for (int f : faces) {
    Eigen::Vector3i t;
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles[static_cast<std::size_t>(f)][k];
      int& i = index[static_cast<std::size_t>(v)];
      if (i < 0) {
        i = static_cast<int>(out.mesh.positions.size());
        out.mesh.positions.push_back(mesh.positions[static_cast<std::size_t>(v)]);
      }
      t[k] = i;
    }
    out.mesh.triangles.push_back(t);
    out.source_face.push_back(f);
  }
  return out;
}

// One clustering pass with `cells` cells along the longest side of `box`.
ViewMesh cluster(const Mesh& mesh, const std::vector<int>& faces, const Eigen::AlignedBox3f& box, int cells) {
  const Eigen::Vector3f size = box.sizes();
  const float cell = std::max(size.maxCoeff(), 1e-9f) / static_cast<float>(cells);
  auto key_of = [&](const Eigen::Vector3f& p) {
    const Eigen::Vector3f q = ((p - box.min()) / cell).array().floor();
    auto c = [&](int k) { return static_cast<std::uint64_t>(std::clamp(static_cast<int>(q[k]), 0, cells)); };
    return (c(0) << 42) | (c(1) << 21) | c(2);
  };
  ViewMesh out;
  // Flat tables (a million-triangle part is clustered several times):
  // each cell's cluster, each vertex's cluster (-1 before it is met).
  CellIndex cluster_of(std::min(3 * faces.size(), mesh.positions.size()) / 4);  // grows as needed
  std::vector<Eigen::Vector3d> sums;
  std::vector<int> counts;
  std::vector<int> vertex_cluster(mesh.positions.size(), -1);
  CellIndex seen(faces.size() / 4);  // output triangles, by their sorted clusters
  for (int f : faces) {
    std::array<int, 3> t{};
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles[static_cast<std::size_t>(f)][k];
      int& found = vertex_cluster[static_cast<std::size_t>(v)];
      if (found < 0) {
        const Eigen::Vector3f& p = mesh.positions[static_cast<std::size_t>(v)];
        found = cluster_of.at(key_of(p), static_cast<int>(sums.size()));
        if (found == static_cast<int>(sums.size())) sums.emplace_back(Eigen::Vector3d::Zero()), counts.push_back(0);
        sums[static_cast<std::size_t>(found)] += p.cast<double>();
        ++counts[static_cast<std::size_t>(found)];
      }
      t[static_cast<std::size_t>(k)] = found;
    }
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    std::array<int, 3> sorted = t;
    std::sort(sorted.begin(), sorted.end());
    const std::uint64_t id = (static_cast<std::uint64_t>(sorted[0]) << 42) ^
                             (static_cast<std::uint64_t>(sorted[1]) << 21) ^ static_cast<std::uint64_t>(sorted[2]);
    if (sorted[2] < (1 << 21)) {  // the same triangle twice
      int& met = seen.at(id, 0);
      if (met != 0) continue;
      met = 1;
    }
    out.mesh.triangles.emplace_back(t[0], t[1], t[2]);
    out.source_face.push_back(f);
  }
  out.mesh.positions.resize(sums.size());
  for (std::size_t c = 0; c < sums.size(); ++c)
    out.mesh.positions[c] = (sums[c] / static_cast<double>(counts[c])).cast<float>();
  return out;
}

}  // namespace

ViewMesh view_mesh(const Mesh& mesh, const std::vector<int>& faces, std::size_t max_triangles) {
  if (faces.size() <= max_triangles) return extract(mesh, faces);
  Eigen::AlignedBox3f box;
  for (int f : faces)
    for (int k = 0; k < 3; ++k) box.extend(mesh.positions[static_cast<std::size_t>(mesh.triangles[f][k])]);
  // A surface cut by an n^3 grid keeps about 2 n^2 triangles per unit of
  // area of the bounds' face: start there and coarsen by a fifth until it fits.
  int cells = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(max_triangles) / 2.0)), 2, (1 << 21) - 2);
  ViewMesh out = cluster(mesh, faces, box, cells);
  while (out.mesh.triangles.size() > max_triangles && cells > 2) {
    cells = std::max(2, cells * 4 / 5);
    out = cluster(mesh, faces, box, cells);
  }
  return out;
}

}  // namespace g2p::detail
