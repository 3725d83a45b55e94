// The object's real size at import (ImportOptions::height_m, longest_side_m).
// Generated meshes come normalised to a box of about a metre whatever the
// object is (TRELLIS and Stable Fast 3D to a unit cube, Hunyuan3D to [-1, 1]);
// masses grow steeply with size (a solid's with its cube), so the size is the
// user's to give.
#include "io/real_size.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace g2p::detail {
namespace {

bool positive_or_zero(double v) { return std::isfinite(v) && v >= 0.0; }

// The model-frame axis the file's up axis became.
int up_index(const ImportOptions& options, const ImportInfo& info) {
  if (options.z_up) return 2;
  return info.up_axis == 'X' ? 0 : info.up_axis == 'Y' ? 1 : 2;
}

}  // namespace

Status check_size_options(const ImportOptions& o) {
  if (!positive_or_zero(o.height_m))
    return Status::InvalidArgument("--height must be a positive number of metres (ImportOptions::height_m)");
  if (!positive_or_zero(o.longest_side_m))
    return Status::InvalidArgument(
        "--longest-side must be a positive number of metres (ImportOptions::longest_side_m)");
  if (o.height_m > 0.0 && o.longest_side_m > 0.0)
    return Status::InvalidArgument("--height and --longest-side both set the object's size: give one");
  if ((o.height_m > 0.0 || o.longest_side_m > 0.0) && o.unit_scale > 0.0)
    return Status::InvalidArgument(std::string(o.height_m > 0.0 ? "--height" : "--longest-side") +
                                   " and --unit both set the object's size: give one");
  return Status::Ok();
}

bool looks_normalised(const Eigen::Vector3d& sides) {
  const double longest = sides.maxCoeff();
  return std::abs(longest - 1.0) <= 0.02 || std::abs(longest - 2.0) <= 0.04;
}

Status apply_real_size(const ImportOptions& o, Model& model) {
  ImportInfo& info = model.info;
  const Eigen::Vector3d sides = bounds(model.mesh).sizes();
  if (o.height_m > 0.0 || o.longest_side_m > 0.0) {
    const bool by_height = o.height_m > 0.0;
    const double now = by_height ? sides[up_index(o, info)] : sides.maxCoeff();
    if (!(now > 0.0) || !std::isfinite(now))
      return Status::InvalidArgument(by_height ? "--height: the model has no extent along its up axis (it is flat); "
                                                 "give --longest-side instead"
                                               : "--longest-side: the model has no extent");
    const double scale = (by_height ? o.height_m : o.longest_side_m) / now;
    for (Eigen::Vector3f& p : model.mesh.positions) p = (p.cast<double>() * scale).cast<float>();
    info.unit_scale_m *= scale;
    info.file_to_model.topLeftCorner<3, 3>() *= scale;
    info.scale_source = by_height ? "height" : "longest-side";
    return Status::Ok();
  }
  info.scale_source = o.unit_scale > 0.0 ? "unit" : "file";
  if (o.unit_scale > 0.0 || !looks_normalised(sides)) return Status::Ok();
  info.looks_normalised = true;
  char text[400];
  std::snprintf(text, sizeof text,
                "the model looks normalised, as image-to-3D generators write meshes: its longest side is %.3f m "
                "(%.2f x %.2f x %.2f m assumed, as the file says); masses grow steeply with size. "
                "Give the real size with --height or --longest-side (ImportOptions::height_m, longest_side_m)",
                sides.maxCoeff(), sides.x(), sides.y(), sides.z());
  info.warnings.emplace_back(text);
  return Status::Ok();
}

}  // namespace g2p::detail
