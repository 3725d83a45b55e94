// Voxelisation of closed meshes and the Euclidean distance transform.
#include "decompose/voxel_grid.h"

#include "core/distance_transform.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace g2p::detail {

VoxelGrid voxelize(const Mesh& closed, int resolution, int pad) {
  VoxelGrid g;
  const Eigen::AlignedBox3d box = bounds(closed);
  if (box.isEmpty() || resolution < 1) return g;
  const double longest = std::max(box.sizes().maxCoeff(), 1e-9);
  g.cell_m = longest / resolution;
  for (int a = 0; a < 3; ++a) g.size[a] = std::max(1, static_cast<int>(std::ceil(box.sizes()[a] / g.cell_m))) + 2 * pad;
  // Centre the occupied cells in the grid.
  g.origin = box.center() - 0.5 * g.cell_m * g.size.cast<double>();
  g.occupied.assign(static_cast<std::size_t>(g.size.prod()), 0);

  // Interior: signed crossings of the +z line through each column's centre.
  // The column centres are nudged off the cell lattice so that they do not
  // pass exactly through vertices and edges of grid-aligned meshes.
  const double nudge_x = 1.3e-4 * g.cell_m, nudge_y = 0.7e-4 * g.cell_m;
  std::vector<std::vector<std::pair<double, int>>> crossings(static_cast<std::size_t>(g.size.x()) * g.size.y());
  for (const Eigen::Vector3i& t : closed.triangles) {
    const Eigen::Vector3d a = closed.positions[static_cast<std::size_t>(t[0])].cast<double>();
    const Eigen::Vector3d b = closed.positions[static_cast<std::size_t>(t[1])].cast<double>();
    const Eigen::Vector3d c = closed.positions[static_cast<std::size_t>(t[2])].cast<double>();
    const double nz = (b - a).cross(c - a).z();
    if (nz == 0) continue;  // vertical: the column line misses it
    const double lo_x = std::min({a.x(), b.x(), c.x()}), hi_x = std::max({a.x(), b.x(), c.x()});
    const double lo_y = std::min({a.y(), b.y(), c.y()}), hi_y = std::max({a.y(), b.y(), c.y()});
    const int i0 = std::max(0, static_cast<int>(std::ceil((lo_x - g.origin.x() - nudge_x) / g.cell_m - 0.5)));
    const int i1 =
        std::min(g.size.x() - 1, static_cast<int>(std::floor((hi_x - g.origin.x() - nudge_x) / g.cell_m - 0.5)));
    const int j0 = std::max(0, static_cast<int>(std::ceil((lo_y - g.origin.y() - nudge_y) / g.cell_m - 0.5)));
    const int j1 =
        std::min(g.size.y() - 1, static_cast<int>(std::floor((hi_y - g.origin.y() - nudge_y) / g.cell_m - 0.5)));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const double x = g.origin.x() + (i + 0.5) * g.cell_m + nudge_x;
        const double y = g.origin.y() + (j + 0.5) * g.cell_m + nudge_y;
        // Barycentric coordinates of (x, y) in the projected triangle.
        const double w0 = (b.x() - x) * (c.y() - y) - (b.y() - y) * (c.x() - x);
        const double w1 = (c.x() - x) * (a.y() - y) - (c.y() - y) * (a.x() - x);
        const double w2 = (a.x() - x) * (b.y() - y) - (a.y() - y) * (b.x() - x);
        const bool inside = (w0 >= 0 && w1 >= 0 && w2 >= 0) || (w0 <= 0 && w1 <= 0 && w2 <= 0);
        if (!inside) continue;
        const double sum = w0 + w1 + w2;
        if (sum == 0) continue;
        const double z = (w0 * a.z() + w1 * b.z() + w2 * c.z()) / sum;
        // Going up, a face whose outward normal points down is an entry.
        crossings[static_cast<std::size_t>(i) + static_cast<std::size_t>(g.size.x()) * j].emplace_back(z,
                                                                                                       nz < 0 ? 1 : -1);
      }
  }
  for (int j = 0; j < g.size.y(); ++j)
    for (int i = 0; i < g.size.x(); ++i) {
      auto& column = crossings[static_cast<std::size_t>(i) + static_cast<std::size_t>(g.size.x()) * j];
      if (column.empty()) continue;
      std::sort(column.begin(), column.end());
      int winding = 0;
      std::size_t next = 0;
      for (int k = 0; k < g.size.z(); ++k) {
        const double z = g.origin.z() + (k + 0.5) * g.cell_m;
        while (next < column.size() && column[next].first < z) winding += column[next++].second;
        if (winding > 0) g.occupied[g.index(i, j, k)] = 1;
      }
    }

  // Surface: every cell a triangle passes through, sampled at half a cell.
  auto mark = [&g](const Eigen::Vector3d& p) {
    const Eigen::Vector3d q = (p - g.origin) / g.cell_m;
    const int i = std::clamp(static_cast<int>(std::floor(q.x())), 0, g.size.x() - 1);
    const int j = std::clamp(static_cast<int>(std::floor(q.y())), 0, g.size.y() - 1);
    const int k = std::clamp(static_cast<int>(std::floor(q.z())), 0, g.size.z() - 1);
    g.occupied[g.index(i, j, k)] = 1;
  };
  for (const Eigen::Vector3i& t : closed.triangles) {
    const Eigen::Vector3d a = closed.positions[static_cast<std::size_t>(t[0])].cast<double>();
    const Eigen::Vector3d b = closed.positions[static_cast<std::size_t>(t[1])].cast<double>();
    const Eigen::Vector3d c = closed.positions[static_cast<std::size_t>(t[2])].cast<double>();
    const double longest_edge = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int steps = std::min(4096, static_cast<int>(std::ceil(2.0 * longest_edge / g.cell_m)));
    if (steps <= 1) {
      mark(a), mark(b), mark(c);
      continue;
    }
    for (int u = 0; u <= steps; ++u)
      for (int v = 0; u + v <= steps; ++v) {
        const double s = static_cast<double>(u) / steps, r = static_cast<double>(v) / steps;
        mark(a + s * (b - a) + r * (c - a));
      }
  }
  return g;
}

long fill_enclosed(VoxelGrid& g) {
  const Eigen::Vector3i n = g.size;
  std::vector<std::uint8_t> outside(g.occupied.size(), 0);
  std::vector<Eigen::Vector3i> stack;
  auto visit = [&](int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= n.x() || j >= n.y() || k >= n.z()) return;
    const std::size_t c = g.index(i, j, k);
    if (g.occupied[c] || outside[c]) return;
    outside[c] = 1;
    stack.emplace_back(i, j, k);
  };
  for (int k = 0; k < n.z(); ++k)
    for (int j = 0; j < n.y(); ++j)
      for (int i = 0; i < n.x(); ++i)
        if (i == 0 || j == 0 || k == 0 || i == n.x() - 1 || j == n.y() - 1 || k == n.z() - 1) visit(i, j, k);
  while (!stack.empty()) {
    const Eigen::Vector3i c = stack.back();
    stack.pop_back();
    visit(c.x() - 1, c.y(), c.z());
    visit(c.x() + 1, c.y(), c.z());
    visit(c.x(), c.y() - 1, c.z());
    visit(c.x(), c.y() + 1, c.z());
    visit(c.x(), c.y(), c.z() - 1);
    visit(c.x(), c.y(), c.z() + 1);
  }
  long filled = 0;
  for (std::size_t c = 0; c < g.occupied.size(); ++c)
    if (!g.occupied[c] && !outside[c]) g.occupied[c] = 1, ++filled;
  return filled;
}

std::vector<float> distance_to_occupied(const VoxelGrid& g) {
  const double inf = std::numeric_limits<double>::infinity();
  const std::size_t total = g.occupied.size();
  std::vector<double> sq(total);
  for (std::size_t c = 0; c < total; ++c) sq[c] = g.occupied[c] ? 0.0 : inf;
  squared_distance_transform<double>({g.size.x(), g.size.y(), g.size.z()}, sq, nullptr);
  std::vector<float> out(total);
  for (std::size_t c = 0; c < total; ++c) out[c] = static_cast<float>(std::sqrt(sq[c]) * g.cell_m);
  return out;
}

}  // namespace g2p::detail
