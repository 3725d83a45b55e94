// Private: what a renderer needs to turn a surface hit into colour. Texture
// sampling through a material's UV transform and wrap modes, and the studio
// lighting with a metallic-roughness BRDF. (The sRGB transfer function is
// core/srgb.h.)
#pragma once

#include <Eigen/Core>

#include <vector>

#include "g2p/model.h"
#include "g2p/render.h"

namespace g2p::detail {

// Bilinear sample of a texture at mesh UV `uv` (image convention), after the
// texture's uv_transform and wrap modes. `srgb` converts texels to linear
// before filtering (colour textures). Returns RGBA; (1, 1, 1, 1) for an empty texture.
Eigen::Vector4f sample(const Texture& texture, const Eigen::Vector2f& uv, bool srgb);

// What a surface point looks like.
struct SurfaceSample {
  Eigen::Vector3f base_color{1.f, 1.f, 1.f};  // linear
  float alpha = 1.f;                          // after alpha mode (MASK cut-outs never get here)
  float metallic = 0.f;
  float roughness = 1.f;
  float transmission = 0.f;
};

// Evaluates a material at a point with UV `uv` (ignored without textures).
// `vertex_color` (linear RGBA, the mesh's interpolated Mesh::colors) multiplies
// the base colour factor and texture, as glTF's COLOR_0 does.
SurfaceSample evaluate_material(const SourceMaterial& material, const Eigen::Vector2f& uv,
                                const Eigen::Vector4f& vertex_color = Eigen::Vector4f::Ones());

// Alpha of a material at `uv` (factor times texture times vertex alpha), for MASK cut-outs.
float material_alpha(const SourceMaterial& material, const Eigen::Vector2f& uv, float vertex_alpha = 1.f);

// Radiance leaving the surface towards the camera under `lights` (unit
// directions; studio_lights() by default) and the ambient terms (see shading.cpp), split so callers can weight the
// specular part of transparent surfaces separately. `n` and `v` are unit world vectors with dot(n, v) >= 0;
// `camera_to_world` orients the camera-relative lights.
struct ShadedColor {
  Eigen::Vector3f diffuse = Eigen::Vector3f::Zero();
  Eigen::Vector3f specular = Eigen::Vector3f::Zero();
};
ShadedColor shade(const SurfaceSample& s, const Eigen::Vector3f& n, const Eigen::Vector3f& v,
                  const Eigen::Matrix3f& camera_to_world, const std::vector<CameraLight>& lights);

}  // namespace g2p::detail
