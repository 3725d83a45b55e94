// Appearance and geometry augmentations of g2p_make_dataset (make_dataset.cpp),
// in a header of their own so that the tests can check them directly.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <string_view>
#include <vector>

#include "g2p/mesh.h"
#include "g2p/model.h"
#include "g2p/render.h"

namespace g2p::training {

// The mean colour of an sRGB texture in linear RGB (what a texture far too
// coarse to show any pattern bakes to), weighted by alpha; white when the
// texture is absent or fully transparent.
inline Eigen::Vector3f mean_linear_colour(const Texture& texture) {
  if (texture.empty() || texture.image->channels() < 3) return Eigen::Vector3f::Ones();
  const ImageU8& im = *texture.image;
  float to_linear[256];
  for (int i = 0; i < 256; ++i) {
    const float c = i / 255.f;
    to_linear[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weight = 0;
  for (int y = 0; y < im.height(); ++y)
    for (int x = 0; x < im.width(); ++x) {
      const double w = im.channels() >= 4 ? im.at(x, y, 3) / 255.0 : 1.0;
      for (int c = 0; c < 3; ++c) sum[c] += w * to_linear[im.at(x, y, c)];
      weight += w;
    }
  if (!(weight > 0)) return Eigen::Vector3f::Ones();
  return (sum / weight).cast<float>();
}

// The mesh turned by `yaw` radians about the up axis (+Z), normals with it.
inline void turn(Mesh& mesh, double yaw) {
  const Eigen::Matrix3f r = Eigen::AngleAxisf(static_cast<float>(yaw), Eigen::Vector3f::UnitZ()).toRotationMatrix();
  for (Eigen::Vector3f& p : mesh.positions) p = r * p;
  for (Eigen::Vector3f& n : mesh.normals) n = r * n;
}

// SplitMix64 (Steele, Lea & Flood 2014): a well-mixed 64-bit hash step.
inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// FNV-1a of a string: a seed that is the same on every platform.
inline std::uint64_t fnv1a(std::string_view text) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : text) h = (h ^ c) * 0x100000001b3ULL;
  return h;
}

// Mild geometry noise, as image-to-3D surfaces are bumpy: every vertex moves
// by a Gaussian offset of standard deviation `sigma` (a fraction of the
// bounding box's diagonal) per axis, and its normal tilts by a Gaussian vector
// of standard deviation `tilt` (about that many radians). The noise is a
// function of the vertex's position (its bits, with `seed`), so vertices at
// the same position (split at UV seams or creases) move together and open no
// cracks.
inline void add_geometry_noise(Mesh& mesh, double sigma, double tilt, std::uint64_t seed) {
  const Eigen::AlignedBox3d box = bounds(mesh);
  const double diagonal = box.isEmpty() ? 0.0 : box.diagonal().norm();
  if (!(diagonal > 0)) return;
  constexpr double kTwoPi = 6.283185307179586;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    std::uint64_t h = seed;
    for (int i = 0; i < 3; ++i) {
      const float c = mesh.positions[v][i] == 0.f ? 0.f : mesh.positions[v][i];  // -0 and +0 alike
      std::uint32_t bits = 0;
      static_assert(sizeof bits == sizeof c);
      std::memcpy(&bits, &c, sizeof bits);
      h = splitmix64(h ^ bits);
    }
    double gauss[6];  // Box-Muller from the position's hash stream
    for (int i = 0; i < 6; i += 2) {
      h = splitmix64(h);
      const double u1 = ((h >> 11) + 1.0) / 9007199254740993.0;  // (0, 1]
      h = splitmix64(h);
      const double u2 = (h >> 11) / 9007199254740992.0;  // [0, 1)
      const double r = std::sqrt(-2.0 * std::log(u1));
      gauss[i] = r * std::cos(kTwoPi * u2);
      gauss[i + 1] = r * std::sin(kTwoPi * u2);
    }
    const Eigen::Vector3f offset(gauss[0], gauss[1], gauss[2]), turn(gauss[3], gauss[4], gauss[5]);
    mesh.positions[v] += static_cast<float>(sigma * diagonal) * offset;
    if (v < mesh.normals.size()) mesh.normals[v] = (mesh.normals[v] + static_cast<float>(tilt) * turn).normalized();
  }
}

// sRGB byte to linear, as the renderer reads colour textures.
inline float srgb_to_linear(std::uint8_t byte) {
  const float c = byte / 255.f;
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// Vertex colours from the colour textures, as generators that write no atlas
// store colour per vertex: each vertex takes the texel (nearest, linear RGB)
// at its UV in the base colour texture of the first triangle that uses it;
// vertices of untextured materials, or without UVs, take white. The textures
// stay (the caller drops them); the material factors are not folded in (the
// renderer multiplies them, as glTF COLOR_0 is multiplied).
inline void texture_to_vertex_colours(const Model& model, Mesh& mesh) {
  const std::size_t n = mesh.positions.size();
  std::vector<int> material(n, -1);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const int m = f < mesh.face_source.size() ? mesh.face_source[f].material : -1;
    for (int i = 0; i < 3; ++i) {
      int& slot = material[static_cast<std::size_t>(mesh.triangles[f][i])];
      if (slot < 0) slot = m;
    }
  }
  std::vector<Eigen::Vector4f> colours(n, Eigen::Vector4f::Ones());
  for (std::size_t v = 0; v < n; ++v) {
    if (material[v] < 0 || material[v] >= static_cast<int>(model.materials.size()) || v >= mesh.uvs.size()) continue;
    const Texture& t = model.materials[static_cast<std::size_t>(material[v])].base_color_texture;
    if (t.empty() || t.image->channels() < 3 || t.image->width() < 1 || t.image->height() < 1) continue;
    const Eigen::Vector2f uv = t.uv_transform * mesh.uvs[v].homogeneous();
    const auto wrap = [](float c, int size) {  // repeat; clamp-to-edge and mirror read alike at this scale
      const float f = c - std::floor(c);
      return std::clamp(static_cast<int>(f * static_cast<float>(size)), 0, size - 1);
    };
    const int x = wrap(uv.x(), t.image->width()), y = wrap(uv.y(), t.image->height());
    for (int c = 0; c < 3; ++c) colours[v][c] = srgb_to_linear(t.image->at(x, y, c));
  }
  if (mesh.colors.size() == n)
    for (std::size_t v = 0; v < n; ++v) colours[v] = colours[v].cwiseProduct(mesh.colors[v]);
  mesh.colors = std::move(colours);
}

// Lighting baked into the vertex colours, as image-to-3D generators bake the
// light of the images they learnt from into their colours (the renderer then
// lights the object again). Each vertex's colour is multiplied by the
// irradiance it gets from `directions` directional lights on a Fibonacci
// sphere, each of weight sky + max(0, d . key)^4 + up * max(0, d_z), in the
// vertex's own shadow: a vertex is lit from d where an orthographic depth map
// seen from d reaches it (a shadow map, bias 1 % of the bounding box's
// diagonal). The irradiance is divided by its 95th percentile over the
// vertices and clamped to [floor, 1]. `key` is a unit vector in the mesh's
// frame. Fails only where the renderer does.
inline Status bake_lighting(const Model& model, Mesh& mesh, const Eigen::Vector3f& key, float sky = 0.3f,
                            float up = 0.5f, float floor = 0.12f, int directions = 48, int size = 128) {
  const std::size_t n = mesh.positions.size();
  if (n == 0 || mesh.triangles.empty()) return Status::Ok();
  Model lit = model;  // the renderer holds a reference: a copy with this mesh
  lit.mesh = mesh;
  if (lit.mesh.normals.size() != n) compute_vertex_normals(lit.mesh);
  Result<std::unique_ptr<Renderer>> renderer = renderer_registry().create("embree");
  if (!renderer.ok()) return renderer.status();
  if (Status s = (*renderer)->set_model(lit); !s.ok()) return s;
  ViewOptions vo;
  vo.num_views = directions, vo.layout = ViewLayout::kFibonacci, vo.orthographic = true;
  vo.width = vo.height = size;
  Result<std::vector<Camera>> cameras = make_views(lit.mesh, vo);
  if (!cameras.ok()) return cameras.status();
  const Eigen::AlignedBox3d box = bounds(lit.mesh);
  const double bias = 0.01 * box.diagonal().norm();
  RenderOptions ro;
  ro.shade = false, ro.material_buffers = false, ro.geometry_buffers = true;
  std::vector<double> irradiance(n, 0.0);
  double total = 0;
  View view;
  for (const Camera& camera : *cameras) {
    const Eigen::Vector3d d = -camera.forward();  // towards the light
    const double weight = sky + std::pow(std::max(0.0, d.dot(key.cast<double>())), 4.0) + up * std::max(0.0, d.z());
    total += weight;
    if (Status s = (*renderer)->render_into(camera, ro, view); !s.ok()) return s;
    for (std::size_t v = 0; v < n; ++v) {
      const double cosine = lit.mesh.normals[v].cast<double>().dot(d);
      if (!(cosine > 0)) continue;
      double depth = 0;
      const Eigen::Vector2d px = camera.project(lit.mesh.positions[v].cast<double>(), &depth);
      double nearest = std::numeric_limits<double>::infinity();  // the farthest of the 3x3 pixels: no
      bool inside = false;                                       // self-shadow at silhouettes and edges
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = static_cast<int>(std::floor(px.x())) + dx, y = static_cast<int>(std::floor(px.y())) + dy;
          if (x < 0 || y < 0 || x >= view.depth.width() || y >= view.depth.height()) continue;
          const double z = view.depth.at(x, y, 0);
          nearest = inside ? std::max(nearest, z) : z, inside = true;
        }
      if (!inside || depth <= nearest + bias) irradiance[v] += weight * cosine;
    }
  }
  if (!(total > 0)) return Status::Ok();
  std::vector<double> sorted = irradiance;
  const std::size_t k = std::min(n - 1, static_cast<std::size_t>(0.95 * static_cast<double>(n)));
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k), sorted.end());
  const double scale = sorted[k] > 0 ? 1.0 / sorted[k] : 0.0;
  if (mesh.colors.size() != n) mesh.colors.assign(n, Eigen::Vector4f::Ones());
  for (std::size_t v = 0; v < n; ++v) {
    const float e = std::clamp(static_cast<float>(irradiance[v] * scale), floor, 1.f);
    mesh.colors[v].head<3>() *= e;
  }
  return Status::Ok();
}

// The studio lights (studio_lights()) jittered, as photographs and baked
// textures are lit in many ways: each light's direction moves by a Gaussian
// vector of standard deviation `turn` (then normalised) and its irradiance is
// scaled by a factor drawn from [1 - spread, 1 + spread].
template <class Rng>
std::vector<CameraLight> jittered_studio_lights(Rng& rng, float turn = 0.5f, float spread = 0.5f) {
  std::normal_distribution<float> gauss(0.f, turn);
  std::uniform_real_distribution<float> scale(1.f - spread, 1.f + spread);
  std::vector<CameraLight> lights = studio_lights();
  for (CameraLight& l : lights) {
    Eigen::Vector3f d = l.direction;
    for (int i = 0; i < 3; ++i) d[i] += gauss(rng);
    if (d.norm() > 1e-3f) l.direction = d.normalized();
    l.irradiance *= scale(rng);
  }
  return lights;
}

}  // namespace g2p::training
