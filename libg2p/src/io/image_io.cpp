// Image reading and writing through OpenCV's codecs. Images are exchanged as
// 8-bit with 1, 3 or 4 channels in RGB(A) order; OpenCV's BGR order stays here.
#include "image_io.h"

#include <cstring>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/file_util.h"
#include "g2p/io.h"

namespace g2p {
namespace detail {
namespace {

// Converts any decoded cv::Mat (1-4 channels, 8 or 16 bit) to RGBA8, writing
// straight into the returned image's storage (no intermediate copy: decoded
// textures are up to 4096^2 and fresh memory is costly on virtual machines).
ImageU8 to_rgba8(const cv::Mat& decoded) {
  cv::Mat m = decoded;
  if (m.depth() == CV_16U)
    m.convertTo(m, CV_8U, 1.0 / 257.0);
  else if (m.depth() != CV_8U)
    m.convertTo(m, CV_8U, 255.0);
  if (m.channels() > 4 || m.channels() == 2) cv::extractChannel(m, m, 0);
  ImageU8 out(m.cols, m.rows, 4);
  cv::Mat rgba(m.rows, m.cols, CV_8UC4, out.data());  // a view of `out`
  switch (m.channels()) {
    case 1: cv::cvtColor(m, rgba, cv::COLOR_GRAY2RGBA); break;
    case 3: cv::cvtColor(m, rgba, cv::COLOR_BGR2RGBA); break;
    default: cv::cvtColor(m, rgba, cv::COLOR_BGRA2RGBA); break;
  }
  return out;
}

}  // namespace

Result<ImageU8> decode_image_rgba(const void* bytes, std::size_t size) {
  if (bytes == nullptr || size == 0) return Status::ParseError("empty image data");
  try {
    const cv::Mat buffer(1, static_cast<int>(size), CV_8U, const_cast<void*>(bytes));
    const cv::Mat decoded = cv::imdecode(buffer, cv::IMREAD_UNCHANGED);
    if (decoded.empty())
      return Status::ParseError("image data (" + std::to_string(size) + " bytes) could not be decoded");
    return to_rgba8(decoded);
  } catch (const cv::Exception& e) {
    return Status::ParseError(std::string("image decoder: ") + e.what());
  }
}

Result<std::string> encode_png(const ImageU8& image) {
  const int c = image.channels();
  if (image.empty() || (c != 1 && c != 3 && c != 4)) return Status::InvalidArgument("encode_png: bad image");
  try {
    // A read-only view of the caller's pixels; the colour conversion writes a
    // new matrix (converting into `src` itself would swap the caller's red
    // and blue).
    const cv::Mat src(image.height(), image.width(), CV_8UC(c), const_cast<std::uint8_t*>(image.data()));
    cv::Mat bgr;
    if (c == 1)
      bgr = src;
    else if (c == 3)
      cv::cvtColor(src, bgr, cv::COLOR_RGB2BGR);
    else if (c == 4)
      cv::cvtColor(src, bgr, cv::COLOR_RGBA2BGRA);
    std::vector<std::uint8_t> bytes;
    if (!cv::imencode(".png", bgr, bytes)) return Status::Internal("encode_png: the PNG encoder failed");
    return std::string(bytes.begin(), bytes.end());
  } catch (const cv::Exception& e) {
    return Status::Internal(std::string("encode_png: ") + e.what());
  }
}

Result<ImageU8> read_image_rgba(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return Status::NotFound(path + ": no such image file");
  try {
    const cv::Mat decoded = cv::imread(path, cv::IMREAD_UNCHANGED);
    if (decoded.empty()) return Status::ParseError(path + ": not a readable image");
    return to_rgba8(decoded);
  } catch (const cv::Exception& e) {
    return Status::ParseError(path + ": " + e.what());
  }
}

}  // namespace detail

Result<ImageU8> read_image(const std::string& path) { return detail::read_image_rgba(path); }

Status write_image(const std::string& path, const ImageU8& image) {
  if (image.empty()) return Status::InvalidArgument(path + ": cannot write an empty image");
  const int c = image.channels();
  if (c != 1 && c != 3 && c != 4)
    return Status::InvalidArgument(path + ": cannot write an image with " + std::to_string(c) + " channels");
  try {
    const cv::Mat src(image.height(), image.width(), CV_8UC(c), const_cast<std::uint8_t*>(image.data()));
    cv::Mat bgr;
    if (c == 3)
      cv::cvtColor(src, bgr, cv::COLOR_RGB2BGR);
    else if (c == 4)
      cv::cvtColor(src, bgr, cv::COLOR_RGBA2BGRA);
    else
      bgr = src;
    // Encoded in memory, then written beside the target and renamed, so a
    // failure never leaves half a file and its message is the system's.
    const std::string extension = std::filesystem::path(path).extension().string();
    std::vector<std::uint8_t> bytes;
    if (extension.empty() || !cv::haveImageWriter(path))
      return Status::InvalidArgument(path + ": unknown image extension '" + extension + "' (png, jpg, bmp, tiff)");
    if (!cv::imencode(extension, bgr, bytes)) return Status::Internal(path + ": the image encoder failed");
    return detail::write_file_atomically(path, std::string(bytes.begin(), bytes.end()));
  } catch (const cv::Exception& e) {
    return Status::IoError(path + ": " + e.what());
  }
  return Status::Ok();
}

}  // namespace g2p
