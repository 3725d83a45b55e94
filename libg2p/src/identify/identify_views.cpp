// Views for the identifiers that run networks trained on photographs
// (backends.h): the detector and the classifier.
#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "identify/backends.h"

namespace g2p {

Status detail::for_each_turntable_view(const Renderer& renderer, const Mesh& mesh, int width, int height,
                                       int background, int count, double elevation_deg, const char* who,
                                       const std::function<Status(const View&)>& use,
                                       const std::vector<CameraLight>& lights) {
  ViewOptions o;
  o.num_views = count;
  o.layout = ViewLayout::kTurntable;
  o.elevation_deg = elevation_deg;
  o.width = width;
  o.height = height;
  Result<std::vector<Camera>> cameras = make_views(mesh, o);
  if (!cameras.ok()) return cameras.status().with_context(who);
  RenderOptions r;
  r.material_buffers = r.geometry_buffers = false;
  r.lights = lights;
  if (background >= 0) r.background.fill(static_cast<std::uint8_t>(std::min(background, 255)));
  View view;  // one, reused: fresh memory costs more than rendering (performance.md)
  for (const Camera& camera : *cameras) {
    G2P_RETURN_IF_ERROR(renderer.render_into(camera, r, view).with_context(std::string(who) + ": view"));
    G2P_RETURN_IF_ERROR(use(view));
  }
  return Status::Ok();
}

detail::PixelBox detail::object_box(const View& view) {
  const int w = view.rgb.width(), h = view.rgb.height();
  if (view.face_id.empty()) return {0, 0, w, h};
  PixelBox box{w, h, 0, 0};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (*view.face_id.pixel(x, y) >= 0) {
        box.x1 = std::min(box.x1, x);
        box.y1 = std::min(box.y1, y);
        box.x2 = std::max(box.x2, x + 1);
        box.y2 = std::max(box.y2, y + 1);
      }
  return box;
}

std::vector<std::uint8_t> detail::rgb_on_background(const View& view, int background) {
  const int w = view.rgb.width(), h = view.rgb.height();
  std::vector<std::uint8_t> rgb(view.rgb.data(), view.rgb.data() + static_cast<std::size_t>(w) * h * 3);
  if (background < 0 || view.face_id.empty()) return rgb;
  const auto grey = static_cast<std::uint8_t>(std::min(background, 255));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (*view.face_id.pixel(x, y) < 0) {
        std::uint8_t* p = rgb.data() + (static_cast<std::size_t>(y) * w + x) * 3;
        p[0] = p[1] = p[2] = grey;
      }
  return rgb;
}

Result<std::vector<ImageU8>> classifier_views(const Renderer& renderer, const Mesh& mesh,
                                              const ClassifierViewOptions& options) {
  if (options.size < 8 || options.size > 4096)
    return Status::InvalidArgument("classifier views: size " + std::to_string(options.size) + " is outside 8-4096");
  std::vector<ImageU8> out;
  G2P_RETURN_IF_ERROR(detail::for_each_turntable_view(
      renderer, mesh, 2 * options.size, 2 * options.size, options.background, options.count, options.elevation_deg,
      "classifier views",
      [&](const View& view) {
        ImageU8 crop = classifier_crop(view, options.size, options.background);
        if (!crop.empty()) out.push_back(std::move(crop));
        return Status::Ok();
      },
      options.lights));
  return out;
}

ImageU8 classifier_crop(const View& view, int size, int background) {
  if (view.rgb.empty() || view.rgb.channels() != 3 || size < 1) return ImageU8();
  const detail::PixelBox box = detail::object_box(view);
  if (box.empty()) return ImageU8();
  const int w = view.rgb.width(), h = view.rgb.height();
  const int grey = std::clamp(background, 0, 255);
  std::vector<std::uint8_t> painted = detail::rgb_on_background(view, grey);
  const cv::Mat rgb(h, w, CV_8UC3, painted.data());
  // A square about the object, a margin of 8 % a side, grey beyond the view.
  const int side = static_cast<int>(std::lround(std::max(box.x2 - box.x1, box.y2 - box.y1) * 1.16)) + 1;
  const int cx = (box.x1 + box.x2) / 2, cy = (box.y1 + box.y2) / 2;
  cv::Mat square(side, side, CV_8UC3, cv::Scalar::all(grey));
  const cv::Rect want(cx - side / 2, cy - side / 2, side, side);
  const cv::Rect have = want & cv::Rect(0, 0, w, h);
  rgb(have).copyTo(square(cv::Rect(have.x - want.x, have.y - want.y, have.width, have.height)));
  ImageU8 out(size, size, 3);
  cv::Mat scaled(size, size, CV_8UC3, out.data());
  cv::resize(square, scaled, cv::Size(size, size), 0, 0, cv::INTER_AREA);
  return out;
}

}  // namespace g2p
