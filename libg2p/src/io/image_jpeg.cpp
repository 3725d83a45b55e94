// JPEG through libjpeg-turbo: baseline and progressive, grey, YCbCr and
// CMYK/YCCK (Adobe's inverted CMYK, as Photoshop writes it) to 8-bit RGBA
// with the library's default (accurate integer) transform; RGB(A) and grey
// images to JPEG.
#include <cstdio>  // jpeglib.h needs FILE

#include <jpeglib.h>

#include <csetjmp>
#include <cstdlib>
#include <vector>

#include "io/image_codecs.h"

namespace g2p::detail {
namespace {

struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX] = {0};
};

void on_error(j_common_ptr cinfo) {
  auto* e = reinterpret_cast<JpegError*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, e->message);
  std::longjmp(e->jump, 1);
}

void on_message(j_common_ptr, int) {}  // warnings (a corrupt restart marker): the decoder goes on

bool decode(const std::uint8_t* bytes, std::size_t size, JpegError& err, ImageU8& image,
            std::vector<std::uint8_t>& cmyk) {
  jpeg_decompress_struct cinfo;
  cinfo.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = on_error;
  err.mgr.emit_message = on_message;
  if (setjmp(err.jump)) {
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, bytes, static_cast<unsigned long>(size));
  jpeg_read_header(&cinfo, TRUE);
  if (!check_image_size("JPEG", cinfo.image_width, cinfo.image_height).ok()) {
    std::snprintf(err.message, sizeof err.message, "image too large (%u x %u)", cinfo.image_width, cinfo.image_height);
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  const bool four = cinfo.num_components == 4;  // CMYK or YCCK
  cinfo.out_color_space = four ? JCS_CMYK : JCS_EXT_RGBA;
  jpeg_start_decompress(&cinfo);
  const int w = static_cast<int>(cinfo.output_width), h = static_cast<int>(cinfo.output_height);
  image.reset(w, h, 4);
  if (four) cmyk.resize(static_cast<std::size_t>(w) * 4);
  while (cinfo.output_scanline < cinfo.output_height) {
    std::uint8_t* row = image.data() + static_cast<std::size_t>(cinfo.output_scanline) * w * 4;
    JSAMPROW target = four ? cmyk.data() : row;
    jpeg_read_scanlines(&cinfo, &target, 1);
    if (four) {
      // Adobe's CMYK is stored inverted: each value is already 255 - ink.
      const bool inverted = cinfo.saw_Adobe_marker;
      for (int x = 0; x < w; ++x) {
        int c = cmyk[static_cast<std::size_t>(4 * x)], m = cmyk[static_cast<std::size_t>(4 * x + 1)],
            yy = cmyk[static_cast<std::size_t>(4 * x + 2)], k = cmyk[static_cast<std::size_t>(4 * x + 3)];
        if (!inverted) c = 255 - c, m = 255 - m, yy = 255 - yy, k = 255 - k;
        row[4 * x] = static_cast<std::uint8_t>(c * k / 255);
        row[4 * x + 1] = static_cast<std::uint8_t>(m * k / 255);
        row[4 * x + 2] = static_cast<std::uint8_t>(yy * k / 255);
        row[4 * x + 3] = 255;
      }
    }
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  return true;
}

bool encode(const ImageU8& image, int quality, JpegError& err, std::vector<std::uint8_t>& rgb, unsigned char*& out,
            unsigned long& out_size) {
  jpeg_compress_struct cinfo;
  cinfo.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = on_error;
  err.mgr.emit_message = on_message;
  if (setjmp(err.jump)) {
    jpeg_destroy_compress(&cinfo);
    return false;
  }
  jpeg_create_compress(&cinfo);
  jpeg_mem_dest(&cinfo, &out, &out_size);
  const int c = image.channels();
  cinfo.image_width = static_cast<JDIMENSION>(image.width());
  cinfo.image_height = static_cast<JDIMENSION>(image.height());
  cinfo.input_components = c == 1 ? 1 : 3;
  cinfo.in_color_space = c == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, quality, TRUE);
  jpeg_start_compress(&cinfo, TRUE);
  if (c == 4) rgb.resize(static_cast<std::size_t>(image.width()) * 3);
  while (cinfo.next_scanline < cinfo.image_height) {
    const std::uint8_t* src = image.data() + static_cast<std::size_t>(cinfo.next_scanline) * image.width() * c;
    JSAMPROW row = const_cast<JSAMPROW>(src);
    if (c == 4) {  // JPEG has no alpha
      for (int x = 0; x < image.width(); ++x)
        for (int k = 0; k < 3; ++k) rgb[static_cast<std::size_t>(3 * x + k)] = src[4 * x + k];
      row = rgb.data();
    }
    jpeg_write_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_compress(&cinfo);
  jpeg_destroy_compress(&cinfo);
  return true;
}

}  // namespace

Result<ImageU8> decode_jpeg(const std::uint8_t* bytes, std::size_t size) {
  JpegError err;
  ImageU8 image;
  std::vector<std::uint8_t> cmyk;
  if (!decode(bytes, size, err, image, cmyk)) return Status::ParseError(std::string("JPEG: ") + err.message);
  return image;
}

Result<std::string> encode_jpeg(const ImageU8& image, int quality) {
  const int c = image.channels();
  if (image.empty() || (c != 1 && c != 3 && c != 4))
    return Status::InvalidArgument("JPEG: cannot encode an image with " + std::to_string(c) + " channels");
  JpegError err;
  std::vector<std::uint8_t> rgb;
  unsigned char* out = nullptr;
  unsigned long out_size = 0;
  const bool ok = encode(image, quality, err, rgb, out, out_size);
  std::string bytes = ok && out != nullptr ? std::string(reinterpret_cast<const char*>(out), out_size) : std::string();
  std::free(out);  // jpeg_mem_dest's buffer
  if (!ok) return Status::Internal(std::string("JPEG encoder: ") + err.message);
  return bytes;
}

}  // namespace g2p::detail
