// Views for the identifiers that run networks trained on photographs
// (backends.h): the detector and the classifier.
#include <algorithm>

#include "identify/backends.h"

namespace g2p {

Result<std::vector<View>> detail::turntable_views(const Renderer& renderer, const Mesh& mesh, int width, int height,
                                                  int background, int count, double elevation_deg, const char* who) {
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
  if (background >= 0) r.background.fill(static_cast<std::uint8_t>(std::min(background, 255)));
  std::vector<View> views(cameras->size());
  for (std::size_t i = 0; i < views.size(); ++i)
    G2P_RETURN_IF_ERROR(renderer.render_into((*cameras)[i], r, views[i]).with_context(std::string(who) + ": view"));
  return views;
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

}  // namespace g2p
