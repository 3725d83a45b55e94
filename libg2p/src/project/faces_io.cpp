// The project stage's files: faces.csv and a labelled PLY.
#include <cstdio>
#include <cstring>
#include <sstream>

#include "core/file_util.h"
#include "g2p/project.h"

namespace g2p {
namespace {

// RFC 4180: quote fields holding a comma, a quote or a line break.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

Status write_faces_csv(const std::string& path, const Model& model, const Projection& projection,
                       const MaterialTable& table) {
  const Mesh& mesh = model.mesh;
  const std::size_t nf = mesh.triangles.size();
  if (projection.labels.label.size() != nf || projection.face_part.size() != nf)
    return Status::InvalidArgument(path + ": the projection does not belong to this mesh");
  std::string out = "source_mesh,source_face,source_material,source_material_name,label,confidence,area_m2,part\n";
  out.reserve(out.size() + nf * 64);
  char numbers[96];
  for (std::size_t f = 0; f < nf; ++f) {
    const FaceSource s = mesh.face_source.empty() ? FaceSource{} : mesh.face_source[f];
    const int label = projection.labels.label[f];
    std::snprintf(numbers, sizeof(numbers), "%d,%d,%d,", s.mesh, s.face, s.material);
    out += numbers;
    out += csv_field(model.material_name(static_cast<int>(f)));
    out += ',';
    out += table.valid_label(label) ? csv_field(table[label].name) : std::string();
    std::snprintf(numbers, sizeof(numbers), ",%.4f,%.9g,%d\n", projection.labels.confidence[f],
                  face_area(mesh, static_cast<int>(f)), projection.face_part[f]);
    out += numbers;
  }
  return detail::write_file_atomically(path, out);
}

Status write_labelled_ply(const std::string& path, const Mesh& mesh, const std::vector<int>& face_labels,
                          const MaterialTable& table) {
  if (face_labels.size() != mesh.triangles.size())
    return Status::InvalidArgument(path + ": one label per face is needed");
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\ncomment libg2p face labels (" << table.name() << ")\n"
         << "element vertex " << mesh.positions.size() << "\nproperty float x\nproperty float y\nproperty float z\n"
         << "element face " << mesh.triangles.size() << "\nproperty list uchar int vertex_indices\n"
         << "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  std::string out = header.str();
  out.reserve(out.size() + mesh.positions.size() * 12 + mesh.triangles.size() * 16);
  for (const Eigen::Vector3f& p : mesh.positions) out.append(reinterpret_cast<const char*>(p.data()), 12);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    out.push_back(3);
    out.append(reinterpret_cast<const char*>(mesh.triangles[f].data()), 12);
    const int l = face_labels[f];
    const std::array<std::uint8_t, 3> c = table.valid_label(l) ? table[l].color : std::array<std::uint8_t, 3>{0, 0, 0};
    out.append(reinterpret_cast<const char*>(c.data()), 3);
  }
  return detail::write_file_atomically(path, out);
}

}  // namespace g2p
