// write_mesh: OBJ, PLY and STL writers for closed part meshes.
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <string>

#include "core/ascii.h"
#include "core/file_util.h"
#include "core/number_text.h"
#include "g2p/io.h"

namespace g2p {

namespace {

template <typename T>
void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));  // little-endian hosts only (x86-64, aarch64)
  out.append(bytes, sizeof(T));
}

std::string obj_text(const Mesh& mesh) {
  std::string s = "# libg2p mesh: " + std::to_string(mesh.num_vertices()) + " vertices, " +
                  std::to_string(mesh.num_faces()) + " triangles, metres\n";
  s.reserve(s.size() + mesh.positions.size() * 40 + mesh.triangles.size() * 24);
  for (const auto& p : mesh.positions) {  // "v x y z", each the shortest text of its float
    s += 'v';
    for (int a = 0; a < 3; ++a) {
      s += ' ';
      detail::append_shortest(s, p[a]);
    }
    s += '\n';
  }
  for (const auto& t : mesh.triangles) {  // "f %d %d %d", from 1
    s += 'f';
    for (int a = 0; a < 3; ++a) {
      s += ' ';
      detail::append_integer(s, t[a] + 1);
    }
    s += '\n';
  }
  return s;
}

std::string ply_bytes(const Mesh& mesh) {
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment libg2p mesh, metres\nelement vertex " +
                    std::to_string(mesh.num_vertices()) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                    std::to_string(mesh.num_faces()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  out.reserve(out.size() + mesh.positions.size() * 12 + mesh.triangles.size() * 13);
  for (const auto& p : mesh.positions)
    for (int a = 0; a < 3; ++a) put<float>(out, p[a]);
  for (const auto& t : mesh.triangles) {
    put<std::uint8_t>(out, 3);
    for (int a = 0; a < 3; ++a) put<std::int32_t>(out, t[a]);
  }
  return out;
}

std::string stl_bytes(const Mesh& mesh) {
  std::string out(80, ' ');
  const char header[] = "libg2p binary STL, metres";
  std::memcpy(out.data(), header, sizeof header - 1);
  put<std::uint32_t>(out, static_cast<std::uint32_t>(mesh.num_faces()));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d n = face_normal(mesh, f);
    for (int a = 0; a < 3; ++a) put<float>(out, static_cast<float>(n[a]));
    for (int c = 0; c < 3; ++c)
      for (int a = 0; a < 3; ++a)
        put<float>(out, mesh.positions[static_cast<std::size_t>(mesh.triangles[static_cast<std::size_t>(f)][c])][a]);
    put<std::uint16_t>(out, 0);
  }
  return out;
}

}  // namespace

Status write_mesh(const std::string& path, const Mesh& mesh) {
  G2P_RETURN_IF_ERROR(validate(mesh));
  const std::size_t dot = path.find_last_of('.');
  const std::string ext = detail::lower_case(dot == std::string::npos ? "" : path.substr(dot + 1));
  if (ext == "obj") return detail::write_file_atomically(path, obj_text(mesh));
  if (ext == "ply") return detail::write_file_atomically(path, ply_bytes(mesh));
  if (ext == "stl") return detail::write_file_atomically(path, stl_bytes(mesh));
  return Status::InvalidArgument("write_mesh: '" + path + "' has no known extension (obj, ply, stl)");
}

}  // namespace g2p
