// Private: the image codecs behind image_io.cpp, each on the library made for
// its format (libpng, libjpeg-turbo, libwebp, libtiff; BMP here), so that
// libg2p does not load OpenCV's imgcodecs and the 90 shared libraries Debian
// builds it against (GDAL, poppler, HDF5, MariaDB, ...). Decoders return
// 8-bit RGBA; their errors name the format and what is wrong.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "g2p/image.h"
#include "g2p/status.h"

namespace g2p::detail {

Result<ImageU8> decode_png(const std::uint8_t* bytes, std::size_t size);   // image_png.cpp
Result<ImageU8> decode_jpeg(const std::uint8_t* bytes, std::size_t size);  // image_jpeg.cpp
Result<ImageU8> decode_webp(const std::uint8_t* bytes, std::size_t size);  // image_webp.cpp
Result<ImageU8> decode_bmp(const std::uint8_t* bytes, std::size_t size);   // image_bmp.cpp
Result<ImageU8> decode_tiff(const std::uint8_t* bytes, std::size_t size);  // image_tiff.cpp

// Encoders take 8-bit images of 1 (grey), 3 (RGB) or 4 (RGBA) channels.
// PNG at zlib level 1 with run-length strategy: fast, as OpenCV wrote them.
Result<std::string> encode_png_bytes(const ImageU8& image);               // image_png.cpp
Result<std::string> encode_jpeg(const ImageU8& image, int quality = 95);  // image_jpeg.cpp; alpha dropped
Result<std::string> encode_bmp(const ImageU8& image);                     // image_bmp.cpp

// An image of `width` x `height` within what a texture can sensibly be
// (at most 32768 a side and 2^28 pixels), else an error naming the format.
Status check_image_size(const char* format, long long width, long long height);

}  // namespace g2p::detail
