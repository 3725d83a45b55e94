// Private: image decoding for textures and image writing (image_codecs.h has the codecs).
#pragma once

#include <cstddef>
#include <string>

#include "g2p/image.h"
#include "g2p/status.h"

namespace g2p::detail {

// Decodes PNG, JPEG, WebP, BMP or TIFF bytes (told by their signature) to 8-bit RGBA.
Result<ImageU8> decode_image_rgba(const void* bytes, std::size_t size);

// PNG bytes of an 8-bit image with 1, 3 (RGB) or 4 (RGBA) channels.
Result<std::string> encode_png(const ImageU8& image);

// Reads an image file to 8-bit RGBA; `bytes`, when given, receives the
// file's bytes as read.
Result<ImageU8> read_image_rgba(const std::string& path, std::string* bytes = nullptr);

// Whether `bytes` are a PNG or a JPEG file (the two image formats glTF itself
// carries): "image/png", "image/jpeg", else nullptr.
const char* gltf_image_mime_type(const std::string& bytes);

}  // namespace g2p::detail
