#include "core/segment_tester.h"

#include <embree3/rtcore.h>

#include <limits>
#include <string>

namespace g2p::detail {

struct SegmentTester::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Impl() {
    if (scene != nullptr) rtcReleaseScene(scene);
    if (device != nullptr) rtcReleaseDevice(device);
  }
};

Result<std::unique_ptr<SegmentTester>> SegmentTester::create(const Mesh& mesh) {
  std::unique_ptr<SegmentTester> t(new SegmentTester());
  t->impl_ = std::make_unique<Impl>();
  Impl& impl = *t->impl_;
  impl.device = rtcNewDevice(nullptr);
  if (impl.device == nullptr) return Status::Internal("complete: Embree device creation failed");
  impl.scene = rtcNewScene(impl.device);
  rtcSetSceneFlags(impl.scene, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry geometry = rtcNewGeometry(impl.device, RTC_GEOMETRY_TYPE_TRIANGLE);
  // Embree reads vertex buffers 16 bytes at a time: one float of padding.
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), mesh.positions.size() + 1));
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(unsigned), mesh.triangles.size()));
  if (vertices == nullptr || indices == nullptr) {
    rtcReleaseGeometry(geometry);
    return Status::Internal("complete: Embree could not allocate the mesh's buffers");
  }
  for (std::size_t v = 0; v < mesh.positions.size(); ++v)
    for (int a = 0; a < 3; ++a) vertices[3 * v + a] = mesh.positions[v][a];
  for (int a = 0; a < 3; ++a) vertices[3 * mesh.positions.size() + a] = 0.f;
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    for (int a = 0; a < 3; ++a) indices[3 * f + a] = static_cast<unsigned>(mesh.triangles[f][a]);
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(impl.scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(impl.scene);
  if (rtcGetDeviceError(impl.device) != RTC_ERROR_NONE) return Status::Internal("complete: Embree scene build failed");
  return t;
}

SegmentTester::~SegmentTester() = default;

bool SegmentTester::crosses(const Eigen::Vector3d& p, const Eigen::Vector3d& q) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray{};
  ray.org_x = static_cast<float>(p.x());
  ray.org_y = static_cast<float>(p.y());
  ray.org_z = static_cast<float>(p.z());
  const Eigen::Vector3d d = q - p;
  ray.dir_x = static_cast<float>(d.x());
  ray.dir_y = static_cast<float>(d.y());
  ray.dir_z = static_cast<float>(d.z());
  ray.tnear = 0.f;
  ray.tfar = 1.f;
  ray.mask = 0xffffffffu;
  ray.flags = 0;
  rtcOccluded1(impl_->scene, &context, &ray);
  return ray.tfar < 0.f;  // Embree sets tfar to -inf on a hit
}

}  // namespace g2p::detail

namespace g2p::detail {

bool SegmentTester::first_hit(const Eigen::Vector3d& p, const Eigen::Vector3d& d, double tmin, double tmax, double& t,
                              int& triangle) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray.org_x = static_cast<float>(p.x());
  rh.ray.org_y = static_cast<float>(p.y());
  rh.ray.org_z = static_cast<float>(p.z());
  rh.ray.dir_x = static_cast<float>(d.x());
  rh.ray.dir_y = static_cast<float>(d.y());
  rh.ray.dir_z = static_cast<float>(d.z());
  rh.ray.tnear = static_cast<float>(tmin);
  rh.ray.tfar = static_cast<float>(tmax);
  rh.ray.mask = 0xffffffffu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  t = rh.ray.tfar;
  triangle = static_cast<int>(rh.hit.primID);
  return true;
}

}  // namespace g2p::detail
