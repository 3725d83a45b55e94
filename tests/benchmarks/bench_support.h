// Shared fixtures of the benchmarks.
#pragma once

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "g2p/io.h"
#include "g2p/mesh.h"

namespace g2p::bench {

#ifdef G2P_BENCH_SHARED_ASSETS
// A shared asset (../shared/assets/NAME/NAME.glb); throws with the importer's
// message when it cannot be read, so a missing asset stops the benchmark clearly.
inline Model load_shared_asset(const std::string& name, const ImportOptions& options = {}) {
  Result<Model> m = load_model(std::string(G2P_BENCH_SHARED_ASSETS) + "/" + name + "/" + name + ".glb", options);
  if (!m.ok()) throw std::runtime_error(m.status().to_string());
  return std::move(*m);
}
#endif

// Splits every triangle into four at its edge midpoints (shared between
// neighbours), keeping UVs and provenance; the large meshes of the benchmarks.
inline Mesh subdivide(const Mesh& in) {
  Mesh out;
  out.positions = in.positions;
  out.uvs = in.uvs;
  std::unordered_map<std::uint64_t, int> midpoints;
  auto midpoint = [&](int a, int b) {
    const std::uint64_t key =
        (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
    auto [it, inserted] = midpoints.emplace(key, static_cast<int>(out.positions.size()));
    if (inserted) {
      out.positions.push_back(0.5f * (out.positions[a] + out.positions[b]));
      if (!out.uvs.empty()) out.uvs.push_back(0.5f * (out.uvs[a] + out.uvs[b]));
    }
    return it->second;
  };
  for (std::size_t f = 0; f < in.triangles.size(); ++f) {
    const Eigen::Vector3i& t = in.triangles[f];
    const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
    for (const Eigen::Vector3i& s : {Eigen::Vector3i(t[0], ab, ca), Eigen::Vector3i(t[1], bc, ab),
                                     Eigen::Vector3i(t[2], ca, bc), Eigen::Vector3i(ab, bc, ca)}) {
      out.triangles.push_back(s);
      if (!in.face_source.empty()) out.face_source.push_back(in.face_source[f]);
    }
  }
  compute_vertex_normals(out);
  return out;
}

}  // namespace g2p::bench
