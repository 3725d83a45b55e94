// Basic geometry of Mesh: bounds, areas, normals, validation.
#include "g2p/mesh.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace g2p {
namespace {

Eigen::Vector3d vertex(const Mesh& mesh, int v) { return mesh.positions[static_cast<std::size_t>(v)].cast<double>(); }

// Twice the area vector of a triangle, in double precision.
Eigen::Vector3d doubled_area_vector(const Mesh& mesh, int face) {
  const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(face)];
  const Eigen::Vector3d a = vertex(mesh, t[0]);
  return (vertex(mesh, t[1]) - a).cross(vertex(mesh, t[2]) - a);
}

}  // namespace

Eigen::AlignedBox3d bounds(const Mesh& mesh) {
  Eigen::AlignedBox3d box;  // empty
  for (const Eigen::Vector3f& p : mesh.positions) box.extend(p.cast<double>());
  return box;
}

double face_area(const Mesh& mesh, int face) { return 0.5 * doubled_area_vector(mesh, face).norm(); }

Eigen::Vector3d face_normal(const Mesh& mesh, int face) {
  const Eigen::Vector3d n = doubled_area_vector(mesh, face);
  const double len = n.norm();
  return len > 0.0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
}

double surface_area(const Mesh& mesh) {
  double sum = 0.0;
  for (int f = 0; f < mesh.num_faces(); ++f) sum += face_area(mesh, f);
  return sum;
}

void compute_vertex_normals(Mesh& mesh) {
  std::vector<Eigen::Vector3d> acc(mesh.positions.size(), Eigen::Vector3d::Zero());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(f)];
    const Eigen::Vector3d n = doubled_area_vector(mesh, f);  // area weight built in
    if (n.squaredNorm() == 0.0) continue;
    for (int k = 0; k < 3; ++k) {
      // Weight by the corner angle too, so a fan of thin triangles does not dominate.
      const Eigen::Vector3d p = vertex(mesh, t[k]);
      const Eigen::Vector3d e1 = (vertex(mesh, t[(k + 1) % 3]) - p).normalized();
      const Eigen::Vector3d e2 = (vertex(mesh, t[(k + 2) % 3]) - p).normalized();
      const double angle = std::acos(std::clamp(e1.dot(e2), -1.0, 1.0));
      acc[static_cast<std::size_t>(t[k])] += angle * n.normalized();
    }
  }
  mesh.normals.resize(mesh.positions.size());
  for (std::size_t v = 0; v < acc.size(); ++v) {
    const double len = acc[v].norm();
    mesh.normals[v] = len > 0.0 ? Eigen::Vector3f((acc[v] / len).cast<float>()) : Eigen::Vector3f::UnitZ();
  }
}

int flag_degenerate_faces(Mesh& mesh, double relative_area_tolerance) {
  const double diag = mesh.positions.empty() ? 0.0 : bounds(mesh).diagonal().norm();
  const double min_area = relative_area_tolerance * diag * diag;
  if (mesh.face_flags.size() != mesh.triangles.size()) mesh.face_flags.assign(mesh.triangles.size(), 0);
  int count = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(f)];
    const bool repeated = t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
    if (repeated || face_area(mesh, f) <= min_area) {
      mesh.face_flags[static_cast<std::size_t>(f)] |= kFaceDegenerate;
      ++count;
    }
  }
  return count;
}

Status validate(const Mesh& mesh) {
  const std::size_t nv = mesh.positions.size();
  const std::size_t nf = mesh.triangles.size();
  auto size_error = [&](const char* what, std::size_t got, std::size_t want, const char* per) {
    return Status::InvalidArgument(std::string(what) + " has " + std::to_string(got) + " entries, expected " +
                                   std::to_string(want) + " (one per " + per + ")");
  };
  if (!mesh.normals.empty() && mesh.normals.size() != nv)
    return size_error("normals", mesh.normals.size(), nv, "vertex");
  if (!mesh.uvs.empty() && mesh.uvs.size() != nv) return size_error("uvs", mesh.uvs.size(), nv, "vertex");
  if (!mesh.colors.empty() && mesh.colors.size() != nv) return size_error("colors", mesh.colors.size(), nv, "vertex");
  if (!mesh.uvs1.empty() && mesh.uvs1.size() != nv) return size_error("uvs1", mesh.uvs1.size(), nv, "vertex");
  if (!mesh.tangents.empty() && mesh.tangents.size() != nv)
    return size_error("tangents", mesh.tangents.size(), nv, "vertex");
  if (!mesh.face_source.empty() && mesh.face_source.size() != nf)
    return size_error("face_source", mesh.face_source.size(), nf, "triangle");
  if (!mesh.face_flags.empty() && mesh.face_flags.size() != nf)
    return size_error("face_flags", mesh.face_flags.size(), nf, "triangle");
  for (std::size_t v = 0; v < nv; ++v) {
    if (!mesh.positions[v].allFinite())
      return Status::InvalidArgument("vertex " + std::to_string(v) + " has a non-finite coordinate");
  }
  for (std::size_t f = 0; f < nf; ++f) {
    const Eigen::Vector3i& t = mesh.triangles[f];
    for (int k = 0; k < 3; ++k) {
      if (t[k] < 0 || static_cast<std::size_t>(t[k]) >= nv)
        return Status::InvalidArgument("face " + std::to_string(f) + ": index " + std::to_string(t[k]) +
                                       " out of range (" + std::to_string(nv) + " vertices)");
    }
  }
  return Status::Ok();
}

}  // namespace g2p
