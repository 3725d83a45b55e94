// What every Model that load_model returns must satisfy, checked by the
// fuzzers after each successful import: a violation is a bug even when
// nothing crashed (downstream stages index with these arrays unchecked).
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "g2p/io.h"
#include "g2p/model.h"

namespace g2p::fuzz {

[[noreturn]] inline void violated(const char* what) {
  std::fprintf(stderr, "model invariant violated: %s\n", what);
  std::abort();
}

inline void check_texture(const Texture& t) {
  if (t.empty()) return;
  const ImageU8& im = *t.image;
  if (im.channels() != 4) violated("a decoded texture is not RGBA");
  if (im.size() != static_cast<std::size_t>(im.width()) * im.height() * 4) violated("texture size != w*h*4");
}

inline void check_model(const Model& model, const ImportOptions& options) {
  const Mesh& m = model.mesh;
  const std::size_t nv = m.positions.size(), nf = m.triangles.size();
  if (nf == 0) violated("an import succeeded with no triangles");
  if (static_cast<long long>(nf) > options.max_faces) violated("more faces than ImportOptions::max_faces");
  if (!m.normals.empty() && m.normals.size() != nv) violated("normals not per vertex");
  if (!m.uvs.empty() && m.uvs.size() != nv) violated("uvs not per vertex");
  if (!m.face_source.empty() && m.face_source.size() != nf) violated("face_source not per face");
  if (!m.face_flags.empty() && m.face_flags.size() != nf) violated("face_flags not per face");
  for (const Eigen::Vector3i& t : m.triangles)
    for (int k = 0; k < 3; ++k)
      if (t[k] < 0 || static_cast<std::size_t>(t[k]) >= nv) violated("a triangle index is out of range");
  for (const Eigen::Vector3f& p : m.positions)
    if (!p.allFinite()) violated("a vertex position is not finite");
  for (const FaceSource& s : m.face_source)
    if (s.material >= static_cast<int>(model.materials.size())) violated("a face names a material that is not there");
  for (const SourcePrimitive& p : model.primitives) {
    if (p.first_face < 0 || p.num_faces < 0 || static_cast<std::size_t>(p.first_face) + p.num_faces > nf)
      violated("a primitive's face range is outside the mesh");
    if (p.first_vertex < 0 || p.num_vertices < 0 || static_cast<std::size_t>(p.first_vertex) + p.num_vertices > nv)
      violated("a primitive's vertex range is outside the mesh");
  }
  for (const SourceMaterial& s : model.materials) {
    check_texture(s.base_color_texture);
    check_texture(s.metallic_roughness_texture);
  }
  // The extent guard: a model that loaded lies inside the accepted size range.
  const double diagonal = bounds(m).diagonal().norm();
  if (!(diagonal <= options.max_extent_m * (1 + 1e-6))) violated("the model is larger than max_extent_m");
}

}  // namespace g2p::fuzz
