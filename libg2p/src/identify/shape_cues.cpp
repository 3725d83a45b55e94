// Shape cues of the kind classifier (identify.h, docs/kind-classifier.md):
// aspect ratios, mirror symmetry and how the surface spreads over the height,
// in the frame of the object's horizontal principal axes, so that they do not
// change with its size, position or turn about the vertical.
#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "g2p/identify.h"

namespace g2p {
namespace {

constexpr int kGrid = 24;  // cells along each axis of the normalised box

int cell(double t) { return std::clamp(static_cast<int>(t * kGrid), 0, kGrid - 1); }

// IoU of an occupancy grid with its mirror image along axis 0 (u) or 1 (v).
double mirror_iou(const std::vector<char>& occ, int axis) {
  int both = 0, either = 0;
  for (int i = 0; i < kGrid; ++i)
    for (int j = 0; j < kGrid; ++j)
      for (int k = 0; k < kGrid; ++k) {
        const int mi = axis == 0 ? kGrid - 1 - i : i, mj = axis == 1 ? kGrid - 1 - j : j;
        const bool a = occ[(i * kGrid + j) * kGrid + k] != 0, b = occ[(mi * kGrid + mj) * kGrid + k] != 0;
        both += a && b;
        either += a || b;
      }
  return either > 0 ? static_cast<double>(both) / either : 0.0;
}

}  // namespace

const std::vector<std::string>& shape_cue_names() {
  static const std::vector<std::string> names = {
      "height_over_long", "short_over_long", "mirror_long", "mirror_short",  "surface_fill",
      "area_height",      "area_bottom",     "area_top",    "footprint_low", "footprint_middle",
      "footprint_high",   "area_level",      "area_upright"};
  return names;
}

std::vector<double> shape_cues(const Mesh& mesh) {
  const int n = mesh.num_vertices();
  // Triangles with area and valid indices; their areas and centroids.
  std::vector<int> faces;
  std::vector<double> area;
  double total = 0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3i& t = mesh.triangles[f];
    if (t.minCoeff() < 0 || t.maxCoeff() >= n) continue;
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>(), b = mesh.positions[t[1]].cast<double>(),
                          c = mesh.positions[t[2]].cast<double>();
    const double s = 0.5 * (b - a).cross(c - a).norm();
    if (!(s > 0) || !std::isfinite(s)) continue;
    faces.push_back(f);
    area.push_back(s);
    total += s;
    mean += s * ((a + b + c) / 3).head<2>();
  }
  if (faces.empty()) return {};
  mean /= total;

  // Horizontal principal axes of the surface: the eigenvectors of its
  // second moment about the centre of area (a triangle's, uniform over its
  // area: A/12 (sum of v v^T over its corners + s s^T, s the corners' sum)).
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (std::size_t i = 0; i < faces.size(); ++i) {
    Eigen::Vector2d v[3], sum = Eigen::Vector2d::Zero();
    Eigen::Matrix2d m = Eigen::Matrix2d::Zero();
    for (int k = 0; k < 3; ++k) {
      v[k] = mesh.positions[mesh.triangles[faces[i]][k]].cast<double>().head<2>() - mean;
      m += v[k] * v[k].transpose(), sum += v[k];
    }
    cov += area[i] / 12 * (m + sum * sum.transpose());
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
  Eigen::Vector2d e_long = eig.eigenvectors().col(1), e_short = eig.eigenvectors().col(0);

  // The object's frame: u along the long axis, v along the short one, z up.
  auto frame = [&](const Eigen::Vector3f& p) {
    const Eigen::Vector2d d = p.cast<double>().head<2>() - mean;
    return Eigen::Vector3d(d.dot(e_long), d.dot(e_short), p.z());
  };
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (int f : faces)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d q = frame(mesh.positions[mesh.triangles[f][k]]);
      lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
    }
  if (hi[1] - lo[1] > hi[0] - lo[0]) {  // the area's long axis is not the extent's: u is the longer side
    std::swap(e_long, e_short);
    std::swap(lo[0], lo[1]), std::swap(hi[0], hi[1]);
  }
  const Eigen::Vector3d extent = hi - lo;
  const double longest = extent.maxCoeff();
  if (!(longest > 0) || !std::isfinite(longest) || extent.minCoeff() < 1e-6 * longest) return {};

  // Surface occupancy of the normalised box, sampling each triangle finely
  // enough to meet every cell it crosses; area by height band; level and
  // upright area.
  std::vector<char> occ(static_cast<std::size_t>(kGrid) * kGrid * kGrid, 0);
  double area_z = 0, bottom = 0, top = 0, level = 0, upright = 0;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const Eigen::Vector3i& t = mesh.triangles[faces[i]];
    Eigen::Vector3d q[3];
    for (int k = 0; k < 3; ++k) q[k] = (frame(mesh.positions[t[k]]) - lo).cwiseQuotient(extent);
    const Eigen::Vector3d p0 = mesh.positions[t[0]].cast<double>(), p1 = mesh.positions[t[1]].cast<double>(),
                          p2 = mesh.positions[t[2]].cast<double>();
    const double nz = std::abs((p1 - p0).cross(p2 - p0).normalized().z());
    const double zc = (q[0].z() + q[1].z() + q[2].z()) / 3;
    area_z += area[i] * zc;
    bottom += zc < 0.25 ? area[i] : 0.0;
    top += zc >= 0.75 ? area[i] : 0.0;
    level += nz > 0.9 ? area[i] : 0.0;
    upright += nz < 0.3 ? area[i] : 0.0;
    const double edge = std::max({(q[1] - q[0]).cwiseAbs().maxCoeff(), (q[2] - q[1]).cwiseAbs().maxCoeff(),
                                  (q[0] - q[2]).cwiseAbs().maxCoeff()});
    const int steps = std::min(4 * kGrid, static_cast<int>(std::ceil(edge * kGrid * 2)) + 1);
    for (int a = 0; a <= steps; ++a)
      for (int b = 0; a + b <= steps; ++b) {
        const double wa = static_cast<double>(a) / steps, wb = static_cast<double>(b) / steps;
        const Eigen::Vector3d x = q[0] + wa * (q[1] - q[0]) + wb * (q[2] - q[0]);
        occ[(cell(x[0]) * kGrid + cell(x[1])) * kGrid + cell(x[2])] = 1;
      }
  }

  // Share of the horizontal grid covered, seen from above, by each third of the height.
  double footprint[3] = {0, 0, 0}, filled = 0;
  for (int band = 0; band < 3; ++band) {
    int covered = 0;
    for (int i = 0; i < kGrid; ++i)
      for (int j = 0; j < kGrid; ++j) {
        bool any = false;
        for (int k = band * kGrid / 3; k < (band + 1) * kGrid / 3 && !any; ++k)
          any = occ[(i * kGrid + j) * kGrid + k] != 0;
        covered += any;
      }
    footprint[band] = static_cast<double>(covered) / (kGrid * kGrid);
  }
  for (char c : occ) filled += c;

  return {std::log(extent[2] / extent[0]),
          std::log(extent[1] / extent[0]),
          mirror_iou(occ, 0),
          mirror_iou(occ, 1),
          filled / occ.size(),
          area_z / total,
          bottom / total,
          top / total,
          footprint[0],
          footprint[1],
          footprint[2],
          level / total,
          upright / total};
}

}  // namespace g2p
