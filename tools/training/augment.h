// Appearance and geometry augmentations of g2p_make_dataset (make_dataset.cpp),
// in a header of their own so that the tests can check them directly.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstring>
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
