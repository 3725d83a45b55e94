// TIFF through libtiff: its first image, any layout libtiff's RGBA reader
// takes (strips or tiles; 1-16 bits; grey, palette, RGB, CMYK, YCbCr; the
// usual compressions), as 8-bit RGBA, top row first.
#include <tiffio.h>

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstring>

#include "io/image_codecs.h"

namespace g2p::detail {
namespace {

struct Memory {
  const std::uint8_t* bytes = nullptr;
  toff_t size = 0, at = 0;
};

tmsize_t read(thandle_t h, void* data, tmsize_t n) {
  auto* m = static_cast<Memory*>(h);
  if (n <= 0 || m->at >= m->size) return 0;
  const toff_t count = std::min<toff_t>(static_cast<toff_t>(n), m->size - m->at);
  std::memcpy(data, m->bytes + m->at, count);
  m->at += count;
  return static_cast<tmsize_t>(count);
}
tmsize_t write(thandle_t, void*, tmsize_t) { return 0; }
toff_t seek(thandle_t h, toff_t offset, int whence) {
  auto* m = static_cast<Memory*>(h);
  const toff_t base = whence == SEEK_CUR ? m->at : whence == SEEK_END ? m->size : 0;
  m->at = base + offset;
  return m->at;
}
int close(thandle_t) { return 0; }
toff_t size_of(thandle_t h) { return static_cast<Memory*>(h)->size; }
int map(thandle_t, void**, toff_t*) { return 0; }
void unmap(thandle_t, void*, toff_t) {}

thread_local std::string* last_error = nullptr;  // the current decode's, for libtiff's global handler

void on_error(const char* module, const char* format, va_list args) {
  if (last_error == nullptr) return;
  char text[512];
  std::vsnprintf(text, sizeof text, format, args);
  *last_error = (module != nullptr ? std::string(module) + ": " : std::string()) + text;
}

}  // namespace

Result<ImageU8> decode_tiff(const std::uint8_t* bytes, std::size_t size) {
  Memory m{bytes, static_cast<toff_t>(size), 0};
  std::string error;
  last_error = &error;
  // libtiff's handlers are process-wide; the error is kept per thread, warnings are dropped.
  TIFFSetErrorHandler(on_error);
  TIFFSetWarningHandler(nullptr);
  TIFF* tif = TIFFClientOpen("texture", "rm", &m, read, write, seek, close, size_of, map, unmap);
  if (tif == nullptr) {
    last_error = nullptr;
    return Status::ParseError("TIFF: " + (error.empty() ? std::string("not a readable TIFF file") : error));
  }
  std::uint32_t w = 0, h = 0;
  TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &w);
  TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &h);
  Status sized = check_image_size("TIFF", w, h);
  ImageU8 image;
  if (sized.ok()) {
    image.reset(static_cast<int>(w), static_cast<int>(h), 4);
    std::uint8_t* px = image.data();
    if (TIFFReadRGBAImageOriented(tif, w, h, reinterpret_cast<std::uint32_t*>(px), ORIENTATION_TOPLEFT, 0) == 0) {
      sized = Status::ParseError("TIFF: " + (error.empty() ? std::string("the image data is not readable") : error));
    } else {
      // One 32-bit word a pixel, A << 24 | B << 16 | G << 8 | R: to bytes R, G, B, A on any machine.
      for (std::size_t i = 0; i < static_cast<std::size_t>(w) * h; ++i) {
        std::uint32_t v;
        std::memcpy(&v, px + 4 * i, 4);
        px[4 * i] = static_cast<std::uint8_t>(TIFFGetR(v));
        px[4 * i + 1] = static_cast<std::uint8_t>(TIFFGetG(v));
        px[4 * i + 2] = static_cast<std::uint8_t>(TIFFGetB(v));
        px[4 * i + 3] = static_cast<std::uint8_t>(TIFFGetA(v));
      }
    }
  }
  TIFFClose(tif);
  last_error = nullptr;
  if (!sized.ok()) return sized;
  return image;
}

}  // namespace g2p::detail
