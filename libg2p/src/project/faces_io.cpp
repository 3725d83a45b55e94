// The project stage's files: faces.csv and a labelled PLY.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>
#include "core/csv.h"
#include "core/file_util.h"
#include "core/json_text.h"
#include "core/number_text.h"
#include "core/parallel.h"
#include "g2p/project.h"
#include "g2p/segment.h"

namespace g2p {

using detail::csv_field;
using detail::csv_fields;

Result<FacesFile> read_faces_csv(const std::string& path, const Mesh& mesh, const MaterialTable& table) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open");
  std::string line;
  if (!std::getline(in, line) || line.rfind("source_mesh,source_face,source_material", 0) != 0)
    return Status::ParseError(path + ": not a libg2p faces.csv (header)");
  const std::size_t nf = mesh.triangles.size();
  FacesFile out;
  out.labels.reserve(nf);
  out.face_part.reserve(nf);
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> f = csv_fields(line);
    auto where = [&] { return path + ":" + std::to_string(line_no) + ": "; };
    if (f.size() != 8) return Status::ParseError(where() + "expected 8 fields, got " + std::to_string(f.size()));
    const std::size_t face = out.labels.size();
    if (face >= nf)
      return Status::InvalidArgument(where() + "more rows than the mesh's " + std::to_string(nf) + " faces");
    if (!mesh.face_source.empty()) {
      const FaceSource& s = mesh.face_source[face];
      if (f[0] != std::to_string(s.mesh) || f[1] != std::to_string(s.face) || f[2] != std::to_string(s.material))
        return Status::InvalidArgument(where() + "the row does not describe face " + std::to_string(face) +
                                       " of this model (another model's faces.csv?)");
    }
    int label = kUnknownLabel;
    if (!f[4].empty()) {
      label = table.find(f[4]);
      if (label == kUnknownLabel) return Status::InvalidArgument(where() + "class '" + f[4] + "' is not in the table");
    }
    char* end = nullptr;
    const long part = std::strtol(f[7].c_str(), &end, 10);
    if (end == f[7].c_str() || *end != '\0' || part < -1 || part >= static_cast<long>(nf))
      return Status::ParseError(where() + "bad part index '" + f[7] + "'");
    out.labels.push_back(label);
    out.face_part.push_back(static_cast<int>(part));
    if (part >= 0) {
      if (out.parts.size() <= static_cast<std::size_t>(part)) out.parts.resize(static_cast<std::size_t>(part) + 1);
      Part& p = out.parts[static_cast<std::size_t>(part)];
      if (!p.faces.empty() && p.label != label)
        return Status::InvalidArgument(where() + "part " + f[7] + " mixes classes");
      p.label = label;
      p.faces.push_back(static_cast<int>(face));
      p.area_m2 += face_area(mesh, static_cast<int>(face));
    }
  }
  if (out.labels.size() != nf)
    return Status::InvalidArgument(path + ": " + std::to_string(out.labels.size()) + " rows for a mesh of " +
                                   std::to_string(nf) + " faces");
  for (std::size_t p = 0; p < out.parts.size(); ++p)
    if (out.parts[p].faces.empty())
      return Status::InvalidArgument(path + ": part " + std::to_string(p) + " has no faces");
  return out;
}

Status write_faces_csv(const std::string& path, const Model& model, const Projection& projection,
                       const MaterialTable& table) {
  const Mesh& mesh = model.mesh;
  const std::size_t nf = mesh.triangles.size();
  if (projection.labels.label.size() != nf || projection.face_part.size() != nf)
    return Status::InvalidArgument(path + ": the projection does not belong to this mesh");
  // Formatted in blocks of faces side by side, joined in order.
  constexpr std::size_t kBlock = 65536;
  std::vector<std::string> blocks((nf + kBlock - 1) / kBlock);
  (void)detail::parallel_each(blocks.size(), [&](std::size_t b) {
    std::string& out = blocks[b];
    const std::size_t end = std::min(nf, (b + 1) * kBlock);
    out.reserve((end - b * kBlock) * 64);
    for (std::size_t f = b * kBlock; f < end; ++f) {
      const FaceSource s = mesh.face_source.empty() ? FaceSource{} : mesh.face_source[f];
      const int label = projection.labels.label[f];
      // As "%d,%d,%d,<name>,<label>,%.4f,%.6g,%d\n".
      detail::append_integer(out, s.mesh);
      out += ',';
      detail::append_integer(out, s.face);
      out += ',';
      detail::append_integer(out, s.material);
      out += ',';
      out += csv_field(model.material_name(static_cast<int>(f)));
      out += ',';
      if (table.valid_label(label)) out += csv_field(table[label].name);
      out += ',';
      detail::append_fixed(out, projection.labels.confidence[f], 4);
      out += ',';
      detail::append_general(out, face_area(mesh, static_cast<int>(f)), 6);
      out += ',';
      detail::append_integer(out, projection.face_part[f]);
      out += '\n';
    }
    return Status::Ok();
  });
  std::size_t size = 0;
  for (const std::string& b : blocks) size += b.size();
  std::string out = "source_mesh,source_face,source_material,source_material_name,label,confidence,area_m2,part\n";
  out.reserve(out.size() + size);
  for (std::string& b : blocks) {
    out += b;
    std::string().swap(b);
  }
  return detail::write_file_atomically(path, out);
}

Status write_labelled_ply(const std::string& path, const Mesh& mesh, const std::vector<int>& face_labels,
                          const MaterialTable& table) {
  if (face_labels.size() != mesh.triangles.size())
    return Status::InvalidArgument(path + ": one label per face is needed");
  // Vertex indices as 16-bit integers where every one fits (a third of the file less).
  const bool short_indices = mesh.positions.size() <= 65535;
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\ncomment libg2p face labels (" << table.name() << ")\n"
         << "element vertex " << mesh.positions.size() << "\nproperty float x\nproperty float y\nproperty float z\n"
         << "element face " << mesh.triangles.size() << "\nproperty list uchar " << (short_indices ? "ushort" : "int")
         << " vertex_indices\n"
         << "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  std::string out = header.str();
  out.reserve(out.size() + mesh.positions.size() * 12 + mesh.triangles.size() * 16);
  for (const Eigen::Vector3f& p : mesh.positions) out.append(reinterpret_cast<const char*>(p.data()), 12);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    out.push_back(3);
    if (short_indices) {
      const std::array<std::uint16_t, 3> t{static_cast<std::uint16_t>(mesh.triangles[f][0]),
                                           static_cast<std::uint16_t>(mesh.triangles[f][1]),
                                           static_cast<std::uint16_t>(mesh.triangles[f][2])};
      out.append(reinterpret_cast<const char*>(t.data()), 6);
    } else {
      out.append(reinterpret_cast<const char*>(mesh.triangles[f].data()), 12);
    }
    const int l = face_labels[f];
    const std::array<std::uint8_t, 3> c = table.valid_label(l) ? table[l].color : std::array<std::uint8_t, 3>{0, 0, 0};
    out.append(reinterpret_cast<const char*>(c.data()), 3);
  }
  return detail::write_file_atomically(path, out);
}

Status write_projection(const std::string& dir, const Model& model, const std::vector<View>& views,
                        const Projection& projection, const MaterialTable& table) {
  std::vector<LabelMap> projected;
  projected.reserve(views.size());
  for (const View& v : views) projected.push_back(render_face_labels(v, projection.labels.label));
  if (!projected.empty()) G2P_RETURN_IF_ERROR(write_label_maps(dir + "/projected", projected, table));
  G2P_RETURN_IF_ERROR(write_faces_csv(dir + "/faces.csv", model, projection, table));
  G2P_RETURN_IF_ERROR(write_labelled_ply(dir + "/labelled.ply", model.mesh, projection.labels.label, table));
  nlohmann::json parts = nlohmann::json::array();
  for (std::size_t i = 0; i < projection.parts.size(); ++i) {
    const Part& p = projection.parts[i];
    parts.push_back({{"part", i},
                     {"label", table.valid_label(p.label) ? table[p.label].name : std::string()},
                     {"faces", p.faces.size()},
                     {"area_m2", p.area_m2}});
  }
  return detail::write_file_atomically(dir + "/parts.json",
                                       detail::json_text(nlohmann::json{{"parts", parts}}, 2) + "\n");
}

}  // namespace g2p
