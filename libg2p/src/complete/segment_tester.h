// Private: does a short segment cross the object's surface? Embree occlusion
// queries in robust (watertight) mode, for the partition completer's
// inside/outside decisions next to the surface.
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

 private:
  SegmentTester() = default;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace g2p::detail
