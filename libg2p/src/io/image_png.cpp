// PNG through libpng: any PNG (palette, grey, alpha, transparency chunk,
// 16-bit, interlaced) to 8-bit RGBA; RGB(A) and grey images to PNG.
#include <png.h>

#include <csetjmp>
#include <cstring>
#include <vector>

#include "io/image_codecs.h"

namespace g2p::detail {
namespace {

struct PngState {
  const std::uint8_t* bytes = nullptr;
  std::size_t size = 0, at = 0;
  std::string error;
  std::string out;  // encoding
  std::jmp_buf jump;
};

void on_error(png_structp png, png_const_charp message) {
  auto* s = static_cast<PngState*>(png_get_error_ptr(png));
  s->error = message != nullptr ? message : "unknown error";
  std::longjmp(s->jump, 1);
}

void on_warning(png_structp, png_const_charp) {}  // a damaged ancillary chunk: libpng goes on

void read_bytes(png_structp png, png_bytep data, png_size_t length) {
  auto* s = static_cast<PngState*>(png_get_io_ptr(png));
  if (length > s->size - s->at) png_error(png, "the data ends inside the image");
  std::memcpy(data, s->bytes + s->at, length);
  s->at += length;
}

void write_bytes(png_structp png, png_bytep data, png_size_t length) {
  static_cast<PngState*>(png_get_io_ptr(png))->out.append(reinterpret_cast<const char*>(data), length);
}

void flush(png_structp) {}

// The decode, apart so that nothing with a destructor lives in the frame that
// setjmp returns to twice.
bool decode(PngState& s, ImageU8& image, std::vector<png_bytep>& rows) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &s, on_error, on_warning);
  if (png == nullptr) {
    s.error = "out of memory";
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr || setjmp(s.jump)) {
    png_destroy_read_struct(&png, &info, nullptr);
    if (s.error.empty()) s.error = "out of memory";
    return false;
  }
  png_set_read_fn(png, &s, read_bytes);
  png_set_user_limits(png, 32768, 32768);
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info), height = png_get_image_height(png, info);
  if (!check_image_size("PNG", width, height).ok()) png_error(png, "image too large");
  const int type = png_get_color_type(png, info);
  // Everything to 8-bit RGBA: palettes and low bit depths expanded, the
  // transparency chunk as alpha, 16 bits scaled (v * 255 / 65535, rounded),
  // grey to RGB, an opaque alpha added where there is none.
  png_set_expand(png);
  png_set_scale_16(png);
  if (type == PNG_COLOR_TYPE_GRAY || type == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
  png_set_filler(png, 0xFF, PNG_FILLER_AFTER);  // does nothing where alpha is already there
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != static_cast<png_size_t>(width) * 4) png_error(png, "unexpected row layout");
  image.reset(static_cast<int>(width), static_cast<int>(height), 4);
  rows.resize(height);
  for (png_uint_32 y = 0; y < height; ++y) rows[y] = image.data() + static_cast<std::size_t>(y) * width * 4;
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

bool encode(PngState& s, const ImageU8& image, std::vector<png_bytep>& rows) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &s, on_error, on_warning);
  if (png == nullptr) {
    s.error = "out of memory";
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr || setjmp(s.jump)) {
    png_destroy_write_struct(&png, &info);
    if (s.error.empty()) s.error = "out of memory";
    return false;
  }
  png_set_write_fn(png, &s, write_bytes, flush);
  const int c = image.channels();
  const int type = c == 1 ? PNG_COLOR_TYPE_GRAY : c == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGB_ALPHA;
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width()), static_cast<png_uint_32>(image.height()), 8, type,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 1);
  png_set_compression_strategy(png, 3);  // Z_RLE
  // One filter, Paeth, instead of libpng's per-row trial of all five: 2.2-2.4x
  // faster on a run's views and label maps, 1-2 % larger (docs/performance.md).
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_PAETH);
  png_write_info(png, info);
  rows.resize(static_cast<std::size_t>(image.height()));
  for (int y = 0; y < image.height(); ++y)
    rows[static_cast<std::size_t>(y)] =
        const_cast<png_bytep>(image.data() + static_cast<std::size_t>(y) * image.width() * c);
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

Result<ImageU8> decode_png(const std::uint8_t* bytes, std::size_t size) {
  PngState s;
  s.bytes = bytes;
  s.size = size;
  ImageU8 image;
  std::vector<png_bytep> rows;
  if (!decode(s, image, rows)) return Status::ParseError("PNG: " + s.error);
  return image;
}

Result<std::string> encode_png_bytes(const ImageU8& image) {
  const int c = image.channels();
  if (image.empty() || (c != 1 && c != 3 && c != 4))
    return Status::InvalidArgument("PNG: cannot encode an image with " + std::to_string(c) + " channels");
  PngState s;
  std::vector<png_bytep> rows;
  if (!encode(s, image, rows)) return Status::Internal("PNG encoder: " + s.error);
  return std::move(s.out);
}

}  // namespace g2p::detail
