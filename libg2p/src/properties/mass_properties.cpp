// Exact mass properties of solids and thin shells bounded by triangle meshes.
//
// Solid: each triangle (a, b, c), taken relative to a reference point r inside
// the mesh's bounding box (for numerical accuracy), closes a tetrahedron with
// r of signed volume V = a . (b x c) / 6; summed over a closed outward mesh
// the signed volumes give the enclosed volume, and the tetrahedra's first and
// second moments give the centre of mass and the covariance
//   C = sum V / 20 (a a^T + b b^T + c c^T + s s^T),  s = a + b + c
// (the second moment of a tetrahedron with a vertex at the origin).
// Shell: each triangle of area A contributes its centroid and
//   sum A / 12 (a a^T + b b^T + c c^T + s s^T)
// (the second moment of a triangle), times rho * t.
// Inertia about a point from the covariance: I = trace(C) Id - C.
// Fill: the same tetrahedra over the triangles clipped to z <= h, with r on the
// plane z = h, so the fill's flat top (in that plane) closes zero-volume
// tetrahedra and need not be built.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "g2p/properties.h"

namespace g2p {
namespace {

Eigen::Matrix3d inertia_from_covariance(const Eigen::Matrix3d& c) {
  return c.trace() * Eigen::Matrix3d::Identity() - c;
}

struct Moments {
  double zeroth = 0.0;                               // volume or area
  Eigen::Vector3d first = Eigen::Vector3d::Zero();   // integral of x
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();  // integral of x x^T
};

// One triangle's contribution, its vertices relative to the reference.
void add(Moments& m, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, double w,
         double first, double second) {
  const Eigen::Vector3d s = a + b + c;
  m.zeroth += w;
  m.first += w * s / first;
  m.second += w / second * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
}

// Moments of the mesh about `reference`. `element` gives a triangle's weight w
// (signed tetrahedron volume or area) from its vertices relative to the
// reference; the first moment adds w s / first, the second
// w / second (a a^T + b b^T + c c^T + s s^T), s = a + b + c.
template <typename Element>
Moments moments(const Mesh& mesh, const Eigen::Vector3d& reference, double first, double second, Element element) {
  Moments m;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>() - reference;
    const Eigen::Vector3d b = mesh.positions[t[1]].cast<double>() - reference;
    const Eigen::Vector3d c = mesh.positions[t[2]].cast<double>() - reference;
    add(m, a, b, c, element(a, b, c), first, second);
  }
  return m;
}

double tetrahedron_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  return a.dot(b.cross(c)) / 6.0;
}

// Volume moments of the part of a closed mesh below z = level, about
// `reference` (which lies on that plane): each triangle clipped to z <= level
// (a triangle, a quadrilateral or nothing), fanned from its first corner.
Moments moments_below(const Mesh& mesh, const Eigen::Vector3d& reference) {
  Moments m;
  std::array<Eigen::Vector3d, 4> kept;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    int n = 0;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = mesh.positions[t[k]].cast<double>() - reference;
      const Eigen::Vector3d q = mesh.positions[t[(k + 1) % 3]].cast<double>() - reference;
      const bool p_in = p.z() <= 0.0, q_in = q.z() <= 0.0;
      if (p_in) kept[static_cast<std::size_t>(n++)] = p;
      if (p_in != q_in) kept[static_cast<std::size_t>(n++)] = p + (q - p) * (p.z() / (p.z() - q.z()));
    }
    for (int k = 1; k + 1 < n; ++k) {
      const Eigen::Vector3d& a = kept[0];
      const Eigen::Vector3d& b = kept[static_cast<std::size_t>(k)];
      const Eigen::Vector3d& c = kept[static_cast<std::size_t>(k + 1)];
      add(m, a, b, c, tetrahedron_volume(a, b, c), 4.0, 20.0);
    }
  }
  return m;
}

// `extent`: the mesh's bounding-box diagonal. A coordinate of the centre of
// mass within 1e-9 of it from zero is zero: the sums' rounding on a
// symmetric solid (-7e-21 m on the hammer's axis) and the float vertices'
// own (a 32-gon handle's 5e-12 m), below what float vertices can place
// (about 1e-7 of the extent).
MassProperties finish(const Moments& m, double mass_per_unit, const Eigen::Vector3d& reference, double area,
                      double extent) {
  MassProperties p;
  p.area_m2 = area;
  p.mass_kg = mass_per_unit * m.zeroth;
  const Eigen::Vector3d com_local = m.first / m.zeroth;
  p.center_of_mass = reference + com_local;
  for (int k = 0; k < 3; ++k)
    if (std::abs(p.center_of_mass[k]) <= 1e-9 * extent) p.center_of_mass[k] = 0.0;
  // Covariance about the centre of mass (parallel-axis shift of the second moment).
  const Eigen::Matrix3d c = mass_per_unit * (m.second - m.zeroth * com_local * com_local.transpose());
  p.inertia = inertia_from_covariance(0.5 * (c + c.transpose()));
  return p;
}

}  // namespace

Eigen::Vector3d MassProperties::principal_moments() const {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia).eigenvalues();
}

Eigen::Matrix3d MassProperties::principal_axes() const {
  Eigen::Matrix3d axes = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia).eigenvectors();
  if (axes.determinant() < 0.0) axes.col(2) = -axes.col(2);
  return axes;
}

Result<MassProperties> solid_mass_properties(const Mesh& mesh, double density_kg_m3) {
  G2P_RETURN_IF_ERROR(validate(mesh).with_context("mass properties"));
  if (mesh.triangles.empty()) return Status::InvalidArgument("mass properties: the mesh has no triangles");
  if (!(density_kg_m3 > 0.0) || !std::isfinite(density_kg_m3))
    return Status::InvalidArgument("mass properties: density must be > 0 kg/m^3");
  const Eigen::Vector3d reference = bounds(mesh).center();
  const Moments m = moments(mesh, reference, 4.0, 20.0, tetrahedron_volume);  // signed tetrahedron volumes
  const double extent = bounds(mesh).diagonal().norm();
  if (!(m.zeroth > 1e-12 * extent * extent * extent))
    return Status::InvalidArgument("mass properties: the enclosed volume is " + std::to_string(m.zeroth) +
                                   " m^3; the mesh must be closed and wound outward (complete it first)");
  MassProperties p = finish(m, density_kg_m3, reference, surface_area(mesh), extent);
  p.volume_m3 = m.zeroth;
  return p;
}

Result<MassProperties> shell_mass_properties(const Mesh& mesh, double density_kg_m3, double thickness_m) {
  G2P_RETURN_IF_ERROR(validate(mesh).with_context("mass properties"));
  if (!(density_kg_m3 > 0.0) || !std::isfinite(density_kg_m3) || !(thickness_m > 0.0) || !std::isfinite(thickness_m))
    return Status::InvalidArgument("mass properties: density and wall thickness must be > 0");
  const Eigen::Vector3d reference = bounds(mesh).center();
  const Moments m = moments(mesh, reference, 3.0, 12.0, [](const auto& a, const auto& b, const auto& c) {
    return 0.5 * (b - a).cross(c - a).norm();  // triangle area
  });
  if (!(m.zeroth > 0.0)) return Status::InvalidArgument("mass properties: the surface has no area");
  MassProperties p = finish(m, density_kg_m3 * thickness_m, reference, m.zeroth, bounds(mesh).diagonal().norm());
  p.volume_m3 = m.zeroth * thickness_m;
  return p;
}

Result<MassProperties> fill_mass_properties(const Mesh& closed, double density_kg_m3, double volume_m3) {
  Result<MassProperties> whole = solid_mass_properties(closed, density_kg_m3);
  if (!whole.ok()) return whole.status().with_context("fill");
  const double enclosed = whole->volume_m3;
  if (!(volume_m3 > 0.0) || !std::isfinite(volume_m3) || volume_m3 > enclosed * (1.0 + 1e-9)) {
    char what[200];
    std::snprintf(what, sizeof what,
                  "fill: a fill of %g m^3 in a volume of %g m^3 (it must be more than 0 and at most all of it)",
                  volume_m3, enclosed);
    return Status::InvalidArgument(what);
  }
  if (volume_m3 >= enclosed) return whole;
  const Eigen::AlignedBox3d box = bounds(closed);
  Eigen::Vector3d reference(box.center().x(), box.center().y(), 0.0);
  // The volume below z = h grows with h from 0 at the bottom to `enclosed` at the top.
  double lo = box.min().z(), hi = box.max().z();
  Moments below;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (!(mid > lo && mid < hi) && i > 0) break;  // as close as doubles get
    reference.z() = mid;
    below = moments_below(closed, reference);
    if (std::abs(below.zeroth - volume_m3) <= 1e-9 * enclosed) break;
    (below.zeroth < volume_m3 ? lo : hi) = reference.z();
  }
  if (!(below.zeroth > 0.0))
    return Status::InvalidArgument("fill: no volume below the level found; is the mesh closed and wound outward?");
  MassProperties p = finish(below, density_kg_m3, reference, 0.0, box.diagonal().norm());
  p.volume_m3 = below.zeroth;
  return p;
}

MassProperties combine(const std::vector<MassProperties>& parts) {
  MassProperties total;
  for (const MassProperties& p : parts) {
    total.mass_kg += p.mass_kg;
    total.volume_m3 += p.volume_m3;
    total.area_m2 += p.area_m2;
    total.center_of_mass += p.mass_kg * p.center_of_mass;
  }
  if (!(total.mass_kg > 0.0)) return total;
  total.center_of_mass /= total.mass_kg;
  for (const MassProperties& p : parts) {
    const Eigen::Vector3d d = p.center_of_mass - total.center_of_mass;
    total.inertia += p.inertia + p.mass_kg * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  }
  return total;
}

}  // namespace g2p
