// Texture sampling and shading for the render stage.
//
// The BRDF is the metallic-roughness model of the glTF 2.0 specification
// (Appendix B): Lambert diffuse plus a GGX/Trowbridge-Reitz microfacet
// specular term with Smith-Schlick visibility and Schlick's Fresnel, with
// alpha = roughness^2 and k = (roughness + 1)^2 / 8 (Karis 2013, "Real Shading
// in Unreal Engine 4").
//
// The default (studio) light set is fixed relative to the camera, so every view
// of every object is lit alike (what a segmenter trained on studio renders
// expects); RenderOptions::lights replaces the three directional lights:
//   key   irradiance 2.4 from the camera's upper left, in front of the object
//   fill  irradiance 0.8 from the right
//   rim   irradiance 1.0 from behind and above the object
//   ambient: a sky/ground hemisphere (0.25 above, 0.10 below, world +Z up) for
//   the diffuse part and a uniform 0.35 environment for the specular part, so
//   metals are never black. No shadows.
#include "render/shading.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/srgb.h"

namespace g2p::detail {
namespace {

constexpr float kPi = 3.14159265358979f;

const std::array<float, 256>& srgb8_lut() {
  static const std::array<float, 256> lut = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[static_cast<std::size_t>(i)] = srgb_to_linear(i / 255.f);
    return t;
  }();
  return lut;
}

int wrap(int i, int n, WrapMode mode) {
  switch (mode) {
    case WrapMode::kClampToEdge: return std::clamp(i, 0, n - 1);
    case WrapMode::kMirroredRepeat: {
      const int m = ((i % (2 * n)) + 2 * n) % (2 * n);
      return m < n ? m : 2 * n - 1 - m;
    }
    case WrapMode::kRepeat: break;
  }
  return ((i % n) + n) % n;
}

constexpr float kSky = 0.25f, kGround = 0.10f, kEnvironment = 0.35f;

}  // namespace

Eigen::Vector4f sample(const Texture& texture, const Eigen::Vector2f& uv, bool srgb) {
  if (!texture.image || texture.image->empty()) return Eigen::Vector4f::Ones();
  const ImageU8& img = *texture.image;
  const Eigen::Vector2f t = texture.uv_transform * Eigen::Vector3f(uv.x(), uv.y(), 1.f);
  const float limit = 1e6f;  // keeps floor() inside int range for absurd coordinates
  const float x = std::isfinite(t.x()) ? std::clamp(t.x() * img.width() - 0.5f, -limit, limit) : 0.f;
  const float y = std::isfinite(t.y()) ? std::clamp(t.y() * img.height() - 0.5f, -limit, limit) : 0.f;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const float ax = x - x0, ay = y - y0;
  const int xs[2] = {wrap(x0, img.width(), texture.wrap_u), wrap(x0 + 1, img.width(), texture.wrap_u)};
  const int ys[2] = {wrap(y0, img.height(), texture.wrap_v), wrap(y0 + 1, img.height(), texture.wrap_v)};
  const float wx[2] = {1.f - ax, ax}, wy[2] = {1.f - ay, ay};
  const std::array<float, 256>& lut = srgb8_lut();
  Eigen::Vector4f out = Eigen::Vector4f::Zero();
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      const std::uint8_t* p = img.pixel(xs[i], ys[j]);
      const float w = wx[i] * wy[j];
      for (int c = 0; c < 3; ++c) out[c] += w * (srgb ? lut[p[c]] : p[c] / 255.f);
      out[3] += w * (p[3] / 255.f);  // alpha is always linear
    }
  }
  return out;
}

float material_alpha(const SourceMaterial& material, const Eigen::Vector2f& uv, float vertex_alpha) {
  float alpha = material.base_color[3] * vertex_alpha;
  if (!material.base_color_texture.empty()) alpha *= sample(material.base_color_texture, uv, false)[3];
  return alpha;
}

SurfaceSample evaluate_material(const SourceMaterial& m, const Eigen::Vector2f& uv,
                                const Eigen::Vector4f& vertex_color) {
  SurfaceSample s;
  Eigen::Vector4f color = m.base_color.cwiseProduct(vertex_color);
  if (!m.base_color_texture.empty()) color = color.cwiseProduct(sample(m.base_color_texture, uv, true));
  s.base_color = color.head<3>();
  s.alpha = m.alpha_mode == AlphaMode::kBlend ? std::clamp(color[3], 0.f, 1.f) : 1.f;
  s.metallic = m.metallic;
  s.roughness = m.roughness;
  if (!m.metallic_roughness_texture.empty()) {
    const Eigen::Vector4f mr = sample(m.metallic_roughness_texture, uv, false);
    s.roughness *= mr[1];  // glTF packing: G = roughness, B = metallic
    s.metallic *= mr[2];
  }
  s.metallic = std::clamp(s.metallic, 0.f, 1.f);
  s.roughness = std::clamp(s.roughness, 0.f, 1.f);
  s.transmission = std::clamp(m.transmission, 0.f, 1.f);
  return s;
}

ShadedColor shade(const SurfaceSample& s, const Eigen::Vector3f& n, const Eigen::Vector3f& v,
                  const Eigen::Matrix3f& camera_to_world, const std::vector<CameraLight>& lights) {
  ShadedColor out;
  const float roughness = std::max(s.roughness, 0.05f);  // a perfect mirror would show no highlight at all
  const float a = roughness * roughness, a2 = a * a;
  const float k = (roughness + 1.f) * (roughness + 1.f) / 8.f;
  const Eigen::Vector3f f0 = Eigen::Vector3f::Constant(0.04f) * (1.f - s.metallic) + s.base_color * s.metallic;
  const Eigen::Vector3f diffuse_color = s.base_color * (1.f - s.metallic);
  const float n_dot_v = std::max(n.dot(v), 1e-4f);
  const float g_v = n_dot_v / (n_dot_v * (1.f - k) + k);

  for (const CameraLight& light : lights) {
    const Eigen::Vector3f l = camera_to_world * light.direction;
    const float n_dot_l = n.dot(l);
    if (n_dot_l <= 0.f) continue;
    const Eigen::Vector3f h = (l + v).normalized();
    const float n_dot_h = std::max(n.dot(h), 0.f), v_dot_h = std::max(v.dot(h), 0.f);
    const float d_denominator = n_dot_h * n_dot_h * (a2 - 1.f) + 1.f;
    const float d = a2 / (kPi * d_denominator * d_denominator);
    const float g = g_v * n_dot_l / (n_dot_l * (1.f - k) + k);
    const float fresnel_weight = std::pow(1.f - v_dot_h, 5.f);
    const Eigen::Vector3f f = f0 + (Eigen::Vector3f::Ones() - f0) * fresnel_weight;
    out.specular += f * (d * g / (4.f * n_dot_v)) * light.irradiance;  // n_dot_l cancels
    out.diffuse += (Eigen::Vector3f::Ones() - f).cwiseProduct(diffuse_color) * (n_dot_l * light.irradiance / kPi);
  }
  // Hemisphere ambient (diffuse) and a uniform environment (specular, with
  // Schlick's Fresnel adjusted for roughness).
  const float up = 0.5f * (1.f + n.z());
  out.diffuse += diffuse_color * (kGround + (kSky - kGround) * up);
  const float fresnel_weight = std::pow(1.f - n_dot_v, 5.f);
  const Eigen::Vector3f f_max = f0.cwiseMax(Eigen::Vector3f::Constant(1.f - roughness));
  out.specular += (f0 + (f_max - f0) * fresnel_weight) * kEnvironment;
  return out;
}

}  // namespace g2p::detail

namespace g2p {

std::vector<CameraLight> studio_lights() {
  return {
      CameraLight{Eigen::Vector3f(-0.4f, -0.6f, -0.7f).normalized(), 2.4f},  // key
      CameraLight{Eigen::Vector3f(0.8f, -0.1f, -0.6f).normalized(), 0.8f},   // fill
      CameraLight{Eigen::Vector3f(0.1f, -0.5f, 0.85f).normalized(), 1.0f},   // rim
  };
}

}  // namespace g2p
