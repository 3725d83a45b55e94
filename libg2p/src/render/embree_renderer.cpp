// The "embree" renderer: one primary ray per pixel through an Embree 3 BVH,
// tiles rendered in parallel with TBB. The first surface a ray meets (alpha
// MASK cut-outs excepted) gives the face ID, depth, normal and material
// buffers; the RGB image composites up to RenderOptions::max_layers
// transparent surfaces (alpha BLEND, KHR_materials_transmission) front to back.
// Surfaces are two-sided: generated meshes often have inconsistent winding.
#include <embree3/rtcore.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <memory>
#include <mutex>

#include "core/srgb.h"
#include "render/backends.h"
#include "render/shading.h"

namespace g2p {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

class EmbreeRenderer final : public Renderer {
 public:
  EmbreeRenderer() = default;
  EmbreeRenderer(const EmbreeRenderer&) = delete;
  EmbreeRenderer& operator=(const EmbreeRenderer&) = delete;
  ~EmbreeRenderer() override {
    release_scene();
    if (device_ != nullptr) rtcReleaseDevice(device_);
  }

  Status set_model(const Model& model) override;
  Status render_into(const Camera& camera, const RenderOptions& options, View& view) const override;

 private:
  struct Hit {
    int face = -1;
    float u = 0.f, v = 0.f, t = 0.f;
    Eigen::Vector3f geometric_normal = Eigen::Vector3f::Zero();
  };

  void release_scene() {
    if (scene_ != nullptr) rtcReleaseScene(scene_);
    scene_ = nullptr;
    model_ = nullptr;
  }

  // Nearest surface along the ray in [t_near, inf); face -1 if none.
  Hit trace(RTCIntersectContext& context, const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
            float t_near) const {
    alignas(16) RTCRayHit rh;
    rh.ray.org_x = origin.x(), rh.ray.org_y = origin.y(), rh.ray.org_z = origin.z();
    rh.ray.dir_x = direction.x(), rh.ray.dir_y = direction.y(), rh.ray.dir_z = direction.z();
    rh.ray.tnear = t_near;
    rh.ray.tfar = kInfinity;
    rh.ray.time = 0.f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &rh);
    Hit hit;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
    hit.face = static_cast<int>(rh.hit.primID);
    hit.u = rh.hit.u;
    hit.v = rh.hit.v;
    hit.t = rh.ray.tfar;
    hit.geometric_normal = Eigen::Vector3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z).normalized();
    return hit;
  }

  const SourceMaterial& material_of(int face) const {
    const int m = face_material_[static_cast<std::size_t>(face)];
    if (m >= 0) return model_->materials[static_cast<std::size_t>(m)];
    // Vertex colours on faces without a material are the colour itself (glTF's
    // default material has a white base colour).
    return model_->mesh.has_colors() ? default_coloured_material_ : default_material_;
  }

  Eigen::Vector2f uv_at(int face, float u, float v) const {
    const Mesh& mesh = model_->mesh;
    if (!mesh.has_uvs()) return Eigen::Vector2f::Zero();
    const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(face)];
    return (1.f - u - v) * mesh.uvs[t[0]] + u * mesh.uvs[t[1]] + v * mesh.uvs[t[2]];
  }

  // Interpolated vertex colour (linear RGBA); white when the mesh has none.
  Eigen::Vector4f color_at(int face, float u, float v) const {
    const Mesh& mesh = model_->mesh;
    if (!mesh.has_colors()) return Eigen::Vector4f::Ones();
    const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(face)];
    return (1.f - u - v) * mesh.colors[t[0]] + u * mesh.colors[t[1]] + v * mesh.colors[t[2]];
  }

  detail::SurfaceSample surface_at(const Hit& hit) const {
    return detail::evaluate_material(material_of(hit.face), uv_at(hit.face, hit.u, hit.v),
                                     color_at(hit.face, hit.u, hit.v));
  }

  // Shading normal facing the viewer (`to_viewer`), from vertex normals when
  // the mesh has them.
  Eigen::Vector3f facing_normal(const Hit& hit, const Eigen::Vector3f& to_viewer) const {
    Eigen::Vector3f ng = hit.geometric_normal;
    if (!ng.allFinite()) ng = to_viewer;
    const bool back = ng.dot(to_viewer) < 0.f;
    if (back) ng = -ng;
    const Mesh& mesh = model_->mesh;
    if (!mesh.has_normals()) return ng;
    const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(hit.face)];
    Eigen::Vector3f n =
        (1.f - hit.u - hit.v) * mesh.normals[t[0]] + hit.u * mesh.normals[t[1]] + hit.v * mesh.normals[t[2]];
    const float len = n.norm();
    if (!(len > 1e-12f)) return ng;
    n /= len;
    if (back) n = -n;
    return n.dot(to_viewer) > 0.f ? n : ng;  // interpolated normals may turn away at silhouettes
  }

  // Embree intersection filter: alpha MASK cut-outs are not surfaces.
  static void alpha_mask_filter(const RTCFilterFunctionNArguments* args) {
    const auto* self = static_cast<const EmbreeRenderer*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
      if (args->valid[i] == 0) continue;
      const int face = static_cast<int>(RTCHitN_primID(args->hit, args->N, i));
      const SourceMaterial& m = self->material_of(face);
      if (m.alpha_mode != AlphaMode::kMask) continue;
      const float u = RTCHitN_u(args->hit, args->N, i), v = RTCHitN_v(args->hit, args->N, i);
      if (detail::material_alpha(m, self->uv_at(face, u, v), self->color_at(face, u, v)[3]) < m.alpha_cutoff)
        args->valid[i] = 0;
    }
  }

  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  const Model* model_ = nullptr;
  float layer_epsilon_ = 1e-5f;  // metres a continued ray skips past a transparent surface
  std::vector<int> face_material_;
  SourceMaterial default_material_ = [] {
    SourceMaterial m;  // faces without a material: light grey dielectric
    m.name = "(none)";
    m.base_color = {0.8f, 0.8f, 0.8f, 1.f};
    m.metallic = 0.f;
    m.roughness = 0.6f;
    return m;
  }();
  SourceMaterial default_coloured_material_ = [this] {
    SourceMaterial m = default_material_;
    m.base_color = Eigen::Vector4f::Ones();
    return m;
  }();
  std::mutex error_mutex_;
  std::string device_error_;
};

Status EmbreeRenderer::set_model(const Model& model) {
  G2P_RETURN_IF_ERROR(validate(model.mesh).with_context("render"));
  if (model.mesh.triangles.empty()) return Status::InvalidArgument("render: the mesh has no triangles");
  if (device_ == nullptr) {
    device_ = rtcNewDevice(nullptr);
    if (device_ == nullptr) return Status::Unavailable("render: Embree could not create a device");
    rtcSetDeviceErrorFunction(
        device_,
        [](void* user, RTCError, const char* message) {
          auto* self = static_cast<EmbreeRenderer*>(user);
          std::lock_guard<std::mutex> lock(self->error_mutex_);  // Embree may report from any thread
          self->device_error_ = message;
        },
        this);
  }
  release_scene();
  device_error_.clear();

  const Mesh& mesh = model.mesh;
  scene_ = rtcNewScene(device_);
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);  // watertight traversal: no rays slip between triangles
  RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), mesh.positions.size()));
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(unsigned), mesh.triangles.size()));
  if (vertices == nullptr || indices == nullptr) {
    rtcReleaseGeometry(geometry);
    release_scene();
    return Status::Internal("render: Embree could not allocate buffers: " + device_error_);
  }
  for (std::size_t v = 0; v < mesh.positions.size(); ++v)
    for (int k = 0; k < 3; ++k) vertices[3 * v + k] = mesh.positions[v][k];
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    for (int k = 0; k < 3; ++k) indices[3 * f + k] = static_cast<unsigned>(mesh.triangles[f][k]);

  model_ = &model;
  face_material_.assign(mesh.triangles.size(), -1);
  for (std::size_t f = 0; f < mesh.face_source.size(); ++f) {
    const int m = mesh.face_source[f].material;
    face_material_[f] = m >= 0 && m < static_cast<int>(model.materials.size()) ? m : -1;
  }
  bool any_mask = false;
  for (const SourceMaterial& m : model.materials) any_mask |= m.alpha_mode == AlphaMode::kMask;
  if (any_mask) {
    rtcSetGeometryUserData(geometry, this);
    rtcSetGeometryIntersectFilterFunction(geometry, &EmbreeRenderer::alpha_mask_filter);
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene_, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene_);
  if (rtcGetDeviceError(device_) != RTC_ERROR_NONE || !device_error_.empty()) {
    release_scene();
    return Status::Internal("render: Embree failed to build the scene: " + device_error_);
  }
  layer_epsilon_ = static_cast<float>(1e-6 * std::max(bounds(mesh).diagonal().norm(), 1e-3));
  return Status::Ok();
}

Status EmbreeRenderer::render_into(const Camera& camera, const RenderOptions& options, View& view) const {
  if (scene_ == nullptr) return Status::InvalidArgument("render: set_model() first");
  G2P_RETURN_IF_ERROR(camera.validate().with_context("render"));
  if (options.tile_size < 1 || options.max_layers < 1)
    return Status::InvalidArgument("render: tile_size and max_layers must be >= 1");
  std::vector<CameraLight> lights = options.lights.empty() ? studio_lights() : options.lights;
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const float length = lights[i].direction.norm();
    if (!(length > 0.f) || !std::isfinite(length) || !(lights[i].irradiance >= 0.f) ||
        !std::isfinite(lights[i].irradiance))
      return Status::InvalidArgument("render: lights[" + std::to_string(i) +
                                     "] needs a finite, non-zero direction and a finite irradiance >= 0");
    lights[i].direction /= length;
  }

  const int w = camera.width, h = camera.height;
  view.camera = camera;
  view.face_id.reset(w, h, 1, -1);
  auto prepare = [&](auto& image, bool wanted, int channels, auto fill) {
    if (wanted)
      image.reset(w, h, channels, fill);
    else
      image.clear();
  };
  prepare(view.rgb, options.shade, 3, std::uint8_t{0});
  prepare(view.depth, options.geometry_buffers, 1, kInfinity);
  prepare(view.normal, options.geometry_buffers, 3, 0.f);
  prepare(view.base_color, options.material_buffers, 4, 0.f);
  prepare(view.metallic_roughness, options.material_buffers, 2, 0.f);
  prepare(view.transmission, options.material_buffers, 1, 0.f);
  const bool first_hit_details = options.geometry_buffers || options.material_buffers;
  const Eigen::Vector3f background(detail::srgb_to_linear(options.background[0] / 255.f),
                                   detail::srgb_to_linear(options.background[1] / 255.f),
                                   detail::srgb_to_linear(options.background[2] / 255.f));
  const Eigen::Matrix3f camera_to_world = camera.rotation.cast<float>();
  const Eigen::Vector3f forward = camera.forward().cast<float>();

  auto render_tile = [&](const tbb::blocked_range2d<int>& tile) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    for (int y = tile.rows().begin(); y != tile.rows().end(); ++y) {
      for (int x = tile.cols().begin(); x != tile.cols().end(); ++x) {
        Eigen::Vector3d o, d;
        camera.ray(x + 0.5, y + 0.5, o, d);
        const Eigen::Vector3f origin = o.cast<float>(), direction = d.cast<float>();
        Hit hit = trace(context, origin, direction, 0.f);
        if (hit.face >= 0) view.face_id.at(x, y) = hit.face;
        if (hit.face < 0 && !options.shade) continue;

        const Eigen::Vector3f to_viewer = -direction;
        if (hit.face >= 0 && first_hit_details) {
          const Eigen::Vector3f n = facing_normal(hit, to_viewer);
          if (options.geometry_buffers) {
            view.depth.at(x, y) = hit.t * direction.dot(forward);
            for (int c = 0; c < 3; ++c) view.normal.at(x, y, c) = n[c];
          }
          if (options.material_buffers) {
            const SourceMaterial& m = material_of(hit.face);
            const detail::SurfaceSample s = surface_at(hit);
            for (int c = 0; c < 3; ++c) view.base_color.at(x, y, c) = s.base_color[c];
            view.base_color.at(x, y, 3) = m.alpha_mode == AlphaMode::kOpaque ? 1.f : s.alpha;
            view.metallic_roughness.at(x, y, 0) = s.metallic;
            view.metallic_roughness.at(x, y, 1) = s.roughness;
            view.transmission.at(x, y) = s.transmission;
          }
        }
        if (!options.shade) continue;

        // Front-to-back compositing through transparent surfaces.
        Eigen::Vector3f color = Eigen::Vector3f::Zero();
        Eigen::Vector3f throughput = Eigen::Vector3f::Ones();
        for (int layer = 0; layer < options.max_layers && hit.face >= 0; ++layer) {
          const detail::SurfaceSample s = surface_at(hit);
          const detail::ShadedColor lit =
              detail::shade(s, facing_normal(hit, to_viewer), to_viewer, camera_to_world, lights);
          // Transmission leaves a faint body colour, keeps the highlights and
          // tints what is seen through it: glass reads as glass.
          // The last layer allowed is treated as opaque rather than dropped.
          const bool last = layer + 1 == options.max_layers;
          const float opacity = last ? 1.f : s.alpha * (1.f - 0.85f * s.transmission);
          color += throughput.cwiseProduct(opacity * lit.diffuse + std::max(opacity, s.transmission) * lit.specular);
          const Eigen::Vector3f tint = Eigen::Vector3f::Ones() * (1.f - s.transmission) + s.base_color * s.transmission;
          throughput = throughput.cwiseProduct(tint) * (1.f - opacity);
          if (throughput.maxCoeff() < 0.01f) break;
          hit = trace(context, origin, direction, hit.t + layer_epsilon_);
        }
        if (hit.face < 0) color += throughput.cwiseProduct(background);
        for (int c = 0; c < 3; ++c) view.rgb.at(x, y, c) = detail::linear_to_srgb8(color[c]);
      }
    }
  };
  tbb::parallel_for(tbb::blocked_range2d<int>(0, h, options.tile_size, 0, w, options.tile_size), render_tile);
  return Status::Ok();
}

}  // namespace

std::unique_ptr<Renderer> make_embree_renderer() { return std::make_unique<EmbreeRenderer>(); }

}  // namespace g2p
