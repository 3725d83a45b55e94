// Private: ray queries against a triangle mesh with Embree in robust
// (watertight) mode: does a short segment cross the surface (the partition
// completer's inside/outside decisions), where does a ray first hit it (the
// properties stage's wall measurements).
#pragma once

#include <Eigen/Core>
#include <memory>

#include "g2p/mesh.h"
#include "g2p/status.h"

namespace g2p::detail {

class SegmentTester {
 public:
  static Result<std::unique_ptr<SegmentTester>> create(const Mesh& mesh);
  ~SegmentTester();
  SegmentTester(const SegmentTester&) = delete;
  SegmentTester& operator=(const SegmentTester&) = delete;

  // True if the open segment (p, q) meets a triangle. Thread-safe.
  bool crosses(const Eigen::Vector3d& p, const Eigen::Vector3d& q) const;

  // The first triangle along the ray p + t d (d of unit length, t in (tmin,
  // tmax)): returns false if none, else its distance t and its index.
  // Thread-safe.
  bool first_hit(const Eigen::Vector3d& p, const Eigen::Vector3d& d, double tmin, double tmax, double& t,
                 int& triangle) const;

 private:
  SegmentTester() = default;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace g2p::detail
