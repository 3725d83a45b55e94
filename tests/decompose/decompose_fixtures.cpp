#include "decompose/decompose_fixtures.h"

#include <cmath>
#include <map>
#include <tuple>

#include "g2p/decompose.h"

namespace g2p::test {

Mesh cells_mesh(const std::vector<std::vector<std::vector<int>>>& cells, float cell_m) {
  const int nz = static_cast<int>(cells.size()), ny = static_cast<int>(cells[0].size()),
            nx = static_cast<int>(cells[0][0].size());
  auto at = [&](int x, int y, int z) {
    return x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz && cells[z][y][x] != 0;
  };
  Mesh m;
  std::map<std::tuple<int, int, int>, int> ids;
  auto vertex = [&](int x, int y, int z) {
    auto [it, added] = ids.emplace(std::make_tuple(x, y, z), m.num_vertices());
    if (added) m.positions.emplace_back(x * cell_m, y * cell_m, z * cell_m);
    return it->second;
  };
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        if (!at(x, y, z)) continue;
        for (int axis = 0; axis < 3; ++axis)
          for (int side = 0; side < 2; ++side) {
            Eigen::Vector3i n = Eigen::Vector3i::Zero();
            n[axis] = side ? 1 : -1;
            if (at(x + n.x(), y + n.y(), z + n.z())) continue;
            // The face's four corners, counter-clockwise seen from outside.
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            Eigen::Vector3i base(x, y, z);
            base[axis] += side;
            std::array<Eigen::Vector3i, 4> c{base, base, base, base};
            c[1][u] += 1;
            c[2][u] += 1;
            c[2][v] += 1;
            c[3][v] += 1;
            std::array<int, 4> id{};
            for (int k = 0; k < 4; ++k) id[k] = vertex(c[k].x(), c[k].y(), c[k].z());
            if (side) {
              m.triangles.emplace_back(id[0], id[1], id[2]);
              m.triangles.emplace_back(id[0], id[2], id[3]);
            } else {
              m.triangles.emplace_back(id[0], id[2], id[1]);
              m.triangles.emplace_back(id[0], id[3], id[2]);
            }
          }
      }
  return m;
}

Mesh revolve(const std::vector<std::array<double, 2>>& profile, int segments) {
  Mesh m;
  std::vector<std::vector<int>> rings;
  const double pi = std::acos(-1.0);
  for (const auto& [r, z] : profile) {
    std::vector<int> ring;
    if (r <= 0) {
      ring.assign(static_cast<std::size_t>(segments), m.num_vertices());
      m.positions.emplace_back(0.0f, 0.0f, static_cast<float>(z));
    } else {
      for (int s = 0; s < segments; ++s) {
        ring.push_back(m.num_vertices());
        const double a = 2 * pi * s / segments;
        m.positions.emplace_back(static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)),
                                 static_cast<float>(z));
      }
    }
    rings.push_back(ring);
  }
  for (std::size_t i = 0; i + 1 < rings.size(); ++i)
    for (int s = 0; s < segments; ++s) {
      const int t = (s + 1) % segments;
      const int a = rings[i][s], b = rings[i][t], c = rings[i + 1][t], d = rings[i + 1][s];
      if (a != b) m.triangles.emplace_back(a, b, c);
      if (c != d) m.triangles.emplace_back(a, c, d);
    }
  if (enclosed_volume(m) < 0)
    for (Eigen::Vector3i& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

Mesh bowl_mesh(double outer_m, double wall_m, int segments) {
  const double inner = outer_m - wall_m;
  std::vector<std::array<double, 2>> profile;
  const int steps = 16;
  const double half_pi = std::acos(0.0);
  for (int i = 0; i <= steps; ++i) {  // outer wall, bottom to rim
    const double phi = -half_pi + half_pi * i / steps;
    profile.push_back({outer_m * std::cos(phi), outer_m + outer_m * std::sin(phi)});
  }
  profile.front()[0] = 0.0;
  for (int i = 0; i <= steps; ++i) {  // inner wall, rim to bottom
    const double phi = -half_pi * i / steps;
    profile.push_back({inner * std::cos(phi), outer_m + inner * std::sin(phi)});
  }
  profile.back()[0] = 0.0;
  return revolve(profile, segments);
}

Mesh u_channel_mesh(float cell_m) {
  // x: 5 cells (wall, 3 open, wall); y: 3 cells; z: base plus 3 cells of wall.
  std::vector<std::vector<std::vector<int>>> cells(4, std::vector<std::vector<int>>(3, std::vector<int>(5, 0)));
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) cells[0][y][x] = 1;
  for (int z = 1; z < 4; ++z)
    for (int y = 0; y < 3; ++y) cells[z][y][0] = cells[z][y][4] = 1;
  return cells_mesh(cells, cell_m);
}

Mesh cup_mesh(double radius_m, double height_m, double wall_m, double bottom_m, int segments) {
  const double inner = radius_m - wall_m;
  return revolve(
      {{0.0, 0.0}, {radius_m, 0.0}, {radius_m, height_m}, {inner, height_m}, {inner, bottom_m}, {0.0, bottom_m}},
      segments);
}

Mesh chair_mesh(float cell_m) {
  std::vector<std::vector<std::vector<int>>> cells(17, std::vector<std::vector<int>>(8, std::vector<int>(8, 0)));
  for (int z = 0; z < 8; ++z)  // legs at the corners
    for (int y : {0, 7})
      for (int x : {0, 7}) cells[z][y][x] = 1;
  for (int y = 0; y < 8; ++y)  // the seat
    for (int x = 0; x < 8; ++x) cells[8][y][x] = 1;
  for (int z = 9; z < 17; ++z)  // the backrest
    for (int x = 0; x < 8; ++x) cells[z][7][x] = 1;
  return cells_mesh(cells, cell_m);
}

Mesh torus_mesh(double major_m, double minor_m, int segments, int sides) {
  Mesh m;
  const double pi = std::acos(-1.0);
  for (int s = 0; s < segments; ++s)
    for (int t = 0; t < sides; ++t) {
      const double a = 2 * pi * s / segments, b = 2 * pi * t / sides;
      const double r = major_m + minor_m * std::cos(b);
      m.positions.emplace_back(static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)),
                               static_cast<float>(minor_m * std::sin(b)));
    }
  for (int s = 0; s < segments; ++s)
    for (int t = 0; t < sides; ++t) {
      const int s1 = (s + 1) % segments, t1 = (t + 1) % sides;
      const int a = s * sides + t, b = s1 * sides + t, c = s1 * sides + t1, d = s * sides + t1;
      m.triangles.emplace_back(a, b, c);
      m.triangles.emplace_back(a, c, d);
    }
  if (enclosed_volume(m) < 0)
    for (Eigen::Vector3i& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

Mesh mug_mesh() {
  Mesh mug = cup_mesh(0.04, 0.1, 0.005, 0.008);
  // The handle: the half of a torus about y at (0.0375, 0, 0.05) with
  // x >= 0.0375, closed by flat caps at x = 0.0375, inside the wall.
  const double pi = std::acos(-1.0), minor = 0.008, major = 0.03;
  const Eigen::Vector3d centre(0.0375, 0.0, 0.05);
  const int segments = 24, sides = 12;
  Mesh h;
  for (int s = 0; s <= segments; ++s)
    for (int t = 0; t < sides; ++t) {
      // From the bottom (-z) around the +x side to the top; the ends are
      // pulled back into the wall (x = 0.0375).
      const double a = -0.5 * pi + pi * s / segments, b = 2 * pi * t / sides;
      const double r = major + minor * std::cos(b);
      const Eigen::Vector3d p = centre + Eigen::Vector3d(r * std::cos(a), minor * std::sin(b), r * std::sin(a));
      h.positions.push_back(p.cast<float>());
    }
  for (int s = 0; s < segments; ++s)
    for (int t = 0; t < sides; ++t) {
      const int t1 = (t + 1) % sides;
      const int a = s * sides + t, b = (s + 1) * sides + t, c = (s + 1) * sides + t1, d = s * sides + t1;
      h.triangles.emplace_back(a, b, c);
      h.triangles.emplace_back(a, c, d);
    }
  for (int end : {0, segments}) {  // a fan over each end ring
    const int middle = h.num_vertices();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int t = 0; t < sides; ++t) sum += h.positions[static_cast<std::size_t>(end * sides + t)].cast<double>();
    h.positions.push_back((sum / sides).cast<float>());
    for (int t = 0; t < sides; ++t) {
      const int a = end * sides + t, b = end * sides + (t + 1) % sides;
      if (end == 0)  // the tube runs the first ring's edges t + 1 -> t, the last ring's t -> t + 1
        h.triangles.emplace_back(middle, a, b);
      else
        h.triangles.emplace_back(middle, b, a);
    }
  }
  if (enclosed_volume(h) < 0)
    for (Eigen::Vector3i& t : h.triangles) std::swap(t[1], t[2]);
  const int offset = mug.num_vertices();
  mug.positions.insert(mug.positions.end(), h.positions.begin(), h.positions.end());
  for (const Eigen::Vector3i& t : h.triangles) mug.triangles.emplace_back(t + Eigen::Vector3i::Constant(offset));
  return mug;
}

Mesh slatted_back_mesh(int slats, float cell_m) {
  const int width = 3 * slats - 2;
  std::vector<std::vector<std::vector<int>>> cells(10, std::vector<std::vector<int>>(1, std::vector<int>(width, 0)));
  for (int x = 0; x < width; ++x) cells[0][0][x] = cells[9][0][x] = 1;  // the rails
  for (int z = 1; z < 9; ++z)
    for (int s = 0; s < slats; ++s) cells[z][0][3 * s] = 1;
  return cells_mesh(cells, cell_m);
}

}  // namespace g2p::test
