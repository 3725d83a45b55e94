// Rendered views on disk: PNG images, the lossless face-ID encoding, depth as
// NumPy .npy, cameras.json and a contact sheet a person can look at.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/file_util.h"
#include "core/json_text.h"
#include "core/parallel.h"
#include "core/srgb.h"
#include "g2p/io.h"
#include "g2p/render.h"

namespace g2p {
namespace {

using nlohmann::json;

constexpr std::int32_t kMaxEncodableFace = (1 << 24) - 2;

json matrix_json(const Eigen::Matrix4d& m) {
  json rows = json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

std::string view_name(std::size_t index, const char* what, const char* ext) {
  char name[64];
  std::snprintf(name, sizeof(name), "view_%02zu_%s.%s", index, what, ext);
  return name;
}

// Linear float channels to 8-bit, sRGB-encoded or not.
ImageU8 to_u8(const ImageF& image, int channels, bool srgb, float scale = 1.f, float offset = 0.f) {
  ImageU8 out(image.width(), image.height(), channels);
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      for (int c = 0; c < channels; ++c) {
        const float v = image.at(x, y, std::min(c, image.channels() - 1)) * scale + offset;
        out.at(x, y, c) =
            srgb ? detail::linear_to_srgb8(v) : static_cast<std::uint8_t>(std::lround(255.f * std::clamp(v, 0.f, 1.f)));
      }
    }
  }
  return out;
}

}  // namespace

Result<ImageU8> encode_face_ids(const ImageI32& face_id) {
  if (face_id.channels() != 1) return Status::InvalidArgument("face-ID image must have one channel");
  ImageU8 out(face_id.width(), face_id.height(), 3);
  for (std::size_t i = 0; i < face_id.size(); ++i) {
    const std::int32_t id = face_id.data()[i];
    if (id < -1 || id > kMaxEncodableFace)
      return Status::Unsupported("face ID " + std::to_string(id) + " does not fit the 24-bit PNG encoding");
    const auto v = static_cast<std::uint32_t>(id + 1);
    std::uint8_t* p = out.data() + 3 * i;
    p[0] = v & 0xFF, p[1] = (v >> 8) & 0xFF, p[2] = (v >> 16) & 0xFF;
  }
  return out;
}

Result<ImageI32> decode_face_ids(const ImageU8& encoded) {
  if (encoded.channels() < 3) return Status::InvalidArgument("face-ID PNG must have 3 or 4 channels");
  ImageI32 out(encoded.width(), encoded.height(), 1);
  for (int y = 0; y < encoded.height(); ++y) {
    for (int x = 0; x < encoded.width(); ++x) {
      const std::uint8_t* p = encoded.pixel(x, y);
      out.at(x, y) = static_cast<std::int32_t>(p[0] | (p[1] << 8) | (p[2] << 16)) - 1;
    }
  }
  return out;
}

std::string cameras_to_json(const std::vector<Camera>& cameras) {
  json views = json::array();
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const Camera& c = cameras[i];
    views.push_back({{"index", i},
                     {"width", c.width},
                     {"height", c.height},
                     {"projection", c.orthographic ? "orthographic" : "perspective"},
                     {"fx", c.fx},
                     {"fy", c.fy},
                     {"cx", c.cx},
                     {"cy", c.cy},
                     {"position", {c.position.x(), c.position.y(), c.position.z()}},
                     {"camera_to_world", matrix_json(c.camera_to_world())},
                     {"world_to_camera", matrix_json(c.world_to_camera())}});
  }
  json doc = {{"format", "g2p-cameras"},
              {"version", 1},
              {"convention",
               "OpenCV: the camera looks along +z, x right, y down; pixel (i, j) has its centre at (i + 0.5, j + "
               "0.5); perspective fx, fy in pixels, orthographic fx, fy in pixels per metre; metres, world +Z up"},
              {"views", views}};
  return detail::json_text(doc, 2) + "\n";
}

Result<std::vector<Camera>> cameras_from_json(const std::string& json_text) {
  const json doc = json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("views") || !doc["views"].is_array())
    return Status::ParseError("cameras JSON: expected an object with a 'views' array");
  std::vector<Camera> cameras;
  for (std::size_t i = 0; i < doc["views"].size(); ++i) {
    const json& v = doc["views"][i];
    const std::string where = "cameras JSON: views[" + std::to_string(i) + "]";
    try {
      Camera c;
      // Whole numbers only: a float such as 2e107 read as int is undefined behaviour.
      for (const char* key : {"width", "height"}) {
        const json& n = v.at(key);
        if (!n.is_number_integer() || n.get<long long>() < 1 || n.get<long long>() > 16384)
          return Status::ParseError(where + ": '" + key + "' must be a whole number of pixels from 1 to 16384, not " +
                                    n.dump());
      }
      c.width = v.at("width").get<int>();
      c.height = v.at("height").get<int>();
      c.orthographic = v.at("projection").get<std::string>() == "orthographic";
      c.fx = v.at("fx").get<double>();
      c.fy = v.at("fy").get<double>();
      c.cx = v.at("cx").get<double>();
      c.cy = v.at("cy").get<double>();
      const json& m = v.at("camera_to_world");
      for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 3; ++k) c.rotation(r, k) = m.at(r).at(k).get<double>();
        c.position[r] = m.at(r).at(3).get<double>();
      }
      G2P_RETURN_IF_ERROR(c.validate().with_context(where));
      cameras.push_back(c);
    } catch (const json::exception& e) {
      return Status::ParseError(where + ": " + e.what());
    }
  }
  return cameras;
}

ImageU8 contact_sheet(const std::vector<const ImageU8*>& images, int columns, int tile, int numbered) {
  columns = std::max(1, std::min<int>(columns, static_cast<int>(images.size())));
  tile = std::max(16, tile);
  const int rows = (static_cast<int>(images.size()) + columns - 1) / columns;
  const int gap = 4;
  cv::Mat sheet(rows * (tile + gap) + gap, columns * (tile + gap) + gap, CV_8UC3, cv::Scalar(40, 40, 40));
  for (std::size_t i = 0; i < images.size(); ++i) {
    const ImageU8* img = images[i];
    if (img == nullptr || img->empty() || img->channels() != 3) continue;
    const cv::Mat src(img->height(), img->width(), CV_8UC3, const_cast<std::uint8_t*>(img->data()));
    const double s = static_cast<double>(tile) / std::max(img->width(), img->height());
    const cv::Size size(std::max(1, static_cast<int>(img->width() * s)),
                        std::max(1, static_cast<int>(img->height() * s)));
    const int col = static_cast<int>(i) % columns, row = static_cast<int>(i) / columns;
    cv::Mat cell = sheet(cv::Rect(gap + col * (tile + gap), gap + row * (tile + gap), size.width, size.height));
    cv::resize(src, cell, size, 0, 0, cv::INTER_AREA);
    if (numbered >= 0 && static_cast<int>(i) >= numbered) continue;
    cv::putText(cell, std::to_string(i), cv::Point(6, 22), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 3);
    cv::putText(cell, std::to_string(i), cv::Point(6, 22), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1);
  }
  ImageU8 out(sheet.cols, sheet.rows, 3);
  std::memcpy(out.data(), sheet.data, out.size());
  return out;
}

Status write_views(const std::string& dir, const std::vector<View>& views, const ViewFileOptions& options) {
  if (views.empty()) return Status::InvalidArgument("write_views: no views");
  G2P_RETURN_IF_ERROR(detail::ensure_directory(dir));
  const std::string base = dir + "/";
  // The views are encoded and written side by side (PNG encoding is most of the time).
  const Status written = detail::parallel_each(views.size(), [&](std::size_t i) -> Status {
    const View& v = views[i];
    if (!v.rgb.empty()) G2P_RETURN_IF_ERROR(write_image(base + view_name(i, "rgb", "png"), v.rgb));
    Result<ImageU8> ids = encode_face_ids(v.face_id);
    if (!ids.ok()) return ids.status().with_context(base + view_name(i, "faceid", "png"));
    G2P_RETURN_IF_ERROR(write_image(base + view_name(i, "faceid", "png"), *ids));
    if (!options.buffers) return Status::Ok();
    if (!v.depth.empty())
      G2P_RETURN_IF_ERROR(
          detail::write_file_atomically(base + view_name(i, "depth", "npy"), detail::npy_float32(v.depth)));
    if (!v.normal.empty())  // n in [-1, 1] shown as (n + 1) / 2
      G2P_RETURN_IF_ERROR(write_image(base + view_name(i, "normal", "png"), to_u8(v.normal, 3, false, 0.5f, 0.5f)));
    if (!v.base_color.empty())
      G2P_RETURN_IF_ERROR(write_image(base + view_name(i, "basecolor", "png"), to_u8(v.base_color, 3, true)));
    if (!v.metallic_roughness.empty()) {  // glTF packing: G = roughness, B = metallic
      ImageF packed(v.metallic_roughness.width(), v.metallic_roughness.height(), 3, 0.f);
      for (int y = 0; y < packed.height(); ++y)
        for (int x = 0; x < packed.width(); ++x) {
          packed.at(x, y, 1) = v.metallic_roughness.at(x, y, 1);
          packed.at(x, y, 2) = v.metallic_roughness.at(x, y, 0);
        }
      G2P_RETURN_IF_ERROR(write_image(base + view_name(i, "metallicroughness", "png"), to_u8(packed, 3, false)));
    }
    if (!v.transmission.empty())
      return write_image(base + view_name(i, "transmission", "png"), to_u8(v.transmission, 1, false));
    return Status::Ok();
  });
  if (!written.ok()) return written;
  std::vector<Camera> cameras;
  std::vector<const ImageU8*> rgb;
  for (const View& v : views) {
    cameras.push_back(v.camera);
    if (!v.rgb.empty()) rgb.push_back(&v.rgb);
  }
  G2P_RETURN_IF_ERROR(detail::write_file_atomically(base + "cameras.json", cameras_to_json(cameras)));
  if (!rgb.empty())
    G2P_RETURN_IF_ERROR(write_image(base + "contact_sheet.png",
                                    contact_sheet(rgb, options.contact_sheet_columns, options.contact_sheet_tile)));
  return Status::Ok();
}

}  // namespace g2p
