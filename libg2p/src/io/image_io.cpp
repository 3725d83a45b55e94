// Image reading and writing (io.h's read_image and write_image, and the
// texture decoder behind the importers): the format is told by the bytes'
// signature, not the file name, and each goes to its codec (image_codecs.h).
// Images are exchanged as 8-bit RGBA when read; written from 1, 3 or 4 channels.
#include "image_io.h"
#include "core/ascii.h"

#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/file_util.h"
#include "g2p/io.h"
#include "io/image_codecs.h"

namespace g2p {
namespace detail {
namespace {

bool starts_with(const std::uint8_t* b, std::size_t size, const char* magic, std::size_t n) {
  return size >= n && std::memcmp(b, magic, n) == 0;
}

}  // namespace

Status check_image_size(const char* format, long long width, long long height) {
  if (width < 1 || height < 1 || width > 32768 || height > 32768 || width * height > (1ll << 28))
    return Status::ParseError(std::string(format) + ": an image of " + std::to_string(width) + " x " +
                              std::to_string(height) + " pixels (at most 32768 a side and 2^28 pixels are read)");
  return Status::Ok();
}

Result<ImageU8> decode_image_rgba(const void* data, std::size_t size) {
  if (data == nullptr || size == 0) return Status::ParseError("empty image data");
  const auto* b = static_cast<const std::uint8_t*>(data);
  if (starts_with(b, size, "\x89PNG\r\n\x1a\n", 8)) return decode_png(b, size);
  if (starts_with(b, size, "\xFF\xD8\xFF", 3)) return decode_jpeg(b, size);
  if (starts_with(b, size, "RIFF", 4) && size >= 12 && std::memcmp(b + 8, "WEBP", 4) == 0) return decode_webp(b, size);
  if (starts_with(b, size, "BM", 2)) return decode_bmp(b, size);
  if (starts_with(b, size, "II*\0", 4) || starts_with(b, size, "MM\0*", 4)) return decode_tiff(b, size);
  const char* named = starts_with(b, size, "\xABKTX 20\xBB", 8)     ? "KTX2"
                      : starts_with(b, size, "DDS ", 4)             ? "DDS"
                      : starts_with(b, size, "GIF8", 4)             ? "GIF"
                      : starts_with(b, size, "\x76\x2F\x31\x01", 4) ? "OpenEXR"
                      : starts_with(b, size, "#?RADIANCE", 10)      ? "Radiance HDR"
                                                                    : nullptr;
  const std::string what = std::string("image data (") + std::to_string(size) + " bytes) ";
  if (named != nullptr)
    return Status::Unsupported(what + "is " + named +
                               ", which libg2p does not read (it reads PNG, JPEG, WebP, BMP "
                               "and TIFF)");
  return Status::ParseError(what + "is not an image libg2p reads (PNG, JPEG, WebP, BMP or TIFF)");
}

Result<std::string> encode_png(const ImageU8& image) { return encode_png_bytes(image); }

Result<ImageU8> read_image_rgba(const std::string& path, std::string* bytes_out) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return Status::NotFound(path + ": no such image file");
  std::ifstream in(path, std::ios::binary);
  std::stringstream bytes;
  if (!in || !(bytes << in.rdbuf())) return Status::IoError(path + ": cannot read it");
  std::string data = bytes.str();
  Result<ImageU8> image = decode_image_rgba(data.data(), data.size());
  if (!image.ok()) return image.status().with_context(path);
  if (bytes_out != nullptr) *bytes_out = std::move(data);
  return image;
}

const char* gltf_image_mime_type(const std::string& bytes) {
  const auto* b = reinterpret_cast<const std::uint8_t*>(bytes.data());
  if (starts_with(b, bytes.size(), "\x89PNG\r\n\x1a\n", 8)) return "image/png";
  if (starts_with(b, bytes.size(), "\xFF\xD8\xFF", 3)) return "image/jpeg";
  return nullptr;
}

}  // namespace detail

Result<ImageU8> read_image(const std::string& path) { return detail::read_image_rgba(path); }

Status write_image(const std::string& path, const ImageU8& image) {
  if (image.empty()) return Status::InvalidArgument(path + ": cannot write an empty image");
  const int c = image.channels();
  if (c != 1 && c != 3 && c != 4)
    return Status::InvalidArgument(path + ": cannot write an image with " + std::to_string(c) + " channels");
  // Encoded in memory, then written beside the target and renamed, so a
  // failure never leaves half a file and its message is the system's.
  const std::string extension = detail::lower_case(std::filesystem::path(path).extension().string());
  if (extension != ".png" && extension != ".jpg" && extension != ".jpeg" && extension != ".bmp")
    return Status::InvalidArgument(path + ": unknown image extension '" + extension + "' (png, jpg, bmp)");
  const Result<std::string> bytes = extension == ".png"   ? detail::encode_png_bytes(image)
                                    : extension == ".bmp" ? detail::encode_bmp(image)
                                                          : detail::encode_jpeg(image);
  if (!bytes.ok()) return bytes.status().with_context(path);
  return detail::write_file_atomically(path, *bytes);
}

}  // namespace g2p
