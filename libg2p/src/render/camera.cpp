// Cameras and view sets: where the render stage looks from.
#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

#include "g2p/render.h"

namespace g2p {
namespace {

constexpr double kPi = 3.14159265358979323846;
double radians(double deg) { return deg * kPi / 180.0; }

// Unit direction from the object's centre towards a camera at the given
// azimuth (0 = in front, on -Y; counter-clockwise seen from above) and elevation.
Eigen::Vector3d direction(double azimuth_rad, double elevation_rad) {
  return {std::sin(azimuth_rad) * std::cos(elevation_rad), -std::cos(azimuth_rad) * std::cos(elevation_rad),
          std::sin(elevation_rad)};
}

std::vector<Eigen::Vector3d> layout_directions(const ViewOptions& o) {
  std::vector<Eigen::Vector3d> dirs;
  const int n = o.num_views;
  switch (o.layout) {
    case ViewLayout::kSphere: {
      if (n == 1) return {direction(0, radians(30))};
      dirs.push_back(Eigen::Vector3d::UnitZ());   // top
      dirs.push_back(-Eigen::Vector3d::UnitZ());  // bottom
      const int ring = n - 2;
      const int upper = (ring + 1) / 2, lower = ring - upper;
      for (int i = 0; i < upper; ++i) dirs.push_back(direction(2 * kPi * i / upper, radians(30)));
      for (int i = 0; i < lower; ++i) dirs.push_back(direction(2 * kPi * (i + 0.5) / lower, radians(-30)));
      break;
    }
    case ViewLayout::kFibonacci: {
      const double golden = kPi * (3.0 - std::sqrt(5.0));
      for (int i = 0; i < n; ++i) {
        const double z = 1.0 - (2.0 * i + 1.0) / n;
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        dirs.emplace_back(r * std::sin(golden * i), -r * std::cos(golden * i), z);
      }
      break;
    }
    case ViewLayout::kTurntable:
      for (int i = 0; i < n; ++i) dirs.push_back(direction(2 * kPi * i / n, radians(o.elevation_deg)));
      break;
  }
  return dirs;
}

}  // namespace

Renderer::~Renderer() = default;

Result<View> Renderer::render(const Camera& camera, const RenderOptions& options) const {
  View view;
  G2P_RETURN_IF_ERROR(render_into(camera, options, view));
  return view;
}

Camera Camera::look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up, int width,
                       int height, double fov_y_deg) {
  Camera c;
  c.width = width;
  c.height = height;
  c.fy = 0.5 * height / std::tan(0.5 * radians(fov_y_deg));
  c.fx = c.fy;  // square pixels
  c.cx = 0.5 * width;
  c.cy = 0.5 * height;
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(up).normalized();  // right
  const Eigen::Vector3d y = z.cross(x);                // down
  c.rotation.col(0) = x;
  c.rotation.col(1) = y;
  c.rotation.col(2) = z;
  c.position = eye;
  return c;
}

Eigen::Matrix3d Camera::intrinsics() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

Eigen::Matrix4d Camera::camera_to_world() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation;
  m.topRightCorner<3, 1>() = position;
  return m;
}

Eigen::Matrix4d Camera::world_to_camera() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation.transpose();
  m.topRightCorner<3, 1>() = -rotation.transpose() * position;
  return m;
}

void Camera::ray(double px, double py, Eigen::Vector3d& origin, Eigen::Vector3d& direction) const {
  const double x = (px - cx) / fx, y = (py - cy) / fy;
  if (orthographic) {
    origin = position + rotation * Eigen::Vector3d(x, y, 0.0);
    direction = forward();
  } else {
    origin = position;
    direction = (rotation * Eigen::Vector3d(x, y, 1.0)).normalized();
  }
}

Eigen::Vector2d Camera::project(const Eigen::Vector3d& world, double* depth) const {
  const Eigen::Vector3d p = rotation.transpose() * (world - position);
  if (depth != nullptr) *depth = p.z();
  if (orthographic) return {fx * p.x() + cx, fy * p.y() + cy};
  return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
}

Status Camera::validate() const {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    return Status::InvalidArgument("camera size " + std::to_string(width) + "x" + std::to_string(height) +
                                   " outside 1..16384 pixels");
  }
  if (!(fx > 0.0 && fy > 0.0 && std::isfinite(fx) && std::isfinite(fy)))
    return Status::InvalidArgument("camera focal lengths must be finite and > 0");
  if (!std::isfinite(cx) || !std::isfinite(cy) || !position.allFinite() || !rotation.allFinite())
    return Status::InvalidArgument("camera has a non-finite parameter");
  if (!(rotation.transpose() * rotation).isIdentity(1e-6) || rotation.determinant() < 0.0)
    return Status::InvalidArgument("camera rotation is not a proper rotation matrix");
  return Status::Ok();
}

Result<std::vector<Camera>> make_views(const Mesh& mesh, const ViewOptions& o) {
  if (o.num_views < 1 || o.num_views > 1000)
    return Status::InvalidArgument("num_views " + std::to_string(o.num_views) + " outside 1..1000");
  if (o.width <= 0 || o.height <= 0 || o.width > 16384 || o.height > 16384)
    return Status::InvalidArgument("view size outside 1..16384 pixels");
  if (!(o.fov_y_deg > 1.0 && o.fov_y_deg < 170.0))
    return Status::InvalidArgument("fov_y_deg must lie in (1, 170) degrees");
  if (!(o.margin >= 1.0 && o.margin < 100.0)) return Status::InvalidArgument("margin must lie in [1, 100)");
  if (mesh.positions.empty()) return Status::InvalidArgument("cannot frame an empty mesh");

  const Eigen::AlignedBox3d box = bounds(mesh);
  const Eigen::Vector3d centre = box.center();
  const double radius = std::max(0.5 * box.diagonal().norm(), 1e-6) * o.margin;
  // The narrower of the two fields of view must hold the sphere.
  const double half_fov_y = 0.5 * radians(o.fov_y_deg);
  const double half_fov_x = std::atan(std::tan(half_fov_y) * o.width / o.height);
  const double distance = radius / std::sin(std::min(half_fov_x, half_fov_y));

  std::vector<Camera> cameras;
  for (const Eigen::Vector3d& d : layout_directions(o)) {
    // Straight up or down, +Y (the object's back) is up in the image.
    const Eigen::Vector3d up = std::abs(d.z()) > 0.999 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
    const double eye_distance = o.orthographic ? 3.0 * radius : distance;
    Camera c = Camera::look_at(centre + eye_distance * d, centre, up, o.width, o.height, o.fov_y_deg);
    if (o.orthographic) {
      c.orthographic = true;
      c.fx = c.fy = 0.5 * std::min(o.width, o.height) / radius;  // pixels per metre
    }
    cameras.push_back(c);
  }
  return cameras;
}

Result<std::vector<View>> render_views(Renderer& renderer, const Model& model, const std::vector<Camera>& cameras,
                                       const RenderOptions& options) {
  G2P_RETURN_IF_ERROR(renderer.set_model(model));
  std::vector<View> views;
  views.reserve(cameras.size());
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    Result<View> v = renderer.render(cameras[i], options);
    if (!v.ok()) return v.status().with_context("view " + std::to_string(i));
    views.push_back(std::move(*v));
  }
  return views;
}

ImageF camera_space_normals(const View& view) {
  const int w = view.face_id.width(), h = view.face_id.height();
  if (view.normal.width() != w || view.normal.height() != h || view.normal.channels() != 3 || w == 0) return {};
  ImageF out(w, h, 3, 0.f);
  const Eigen::Matrix3f to_camera = view.camera.rotation.transpose().cast<float>();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (view.face_id.at(x, y) < 0) continue;
      Eigen::Map<Eigen::Vector3f>(out.pixel(x, y)) =
          to_camera * Eigen::Map<const Eigen::Vector3f>(view.normal.pixel(x, y));
    }
  return out;
}

}  // namespace g2p
