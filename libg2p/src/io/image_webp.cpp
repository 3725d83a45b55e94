// WebP through libwebp (lossy, lossless, with or without alpha; the first
// frame of an animation is not read: libwebp's simple API refuses those).
#include <webp/decode.h>

#include <cstring>

#include "io/image_codecs.h"

namespace g2p::detail {

Result<ImageU8> decode_webp(const std::uint8_t* bytes, std::size_t size) {
  WebPBitstreamFeatures features;
  const VP8StatusCode status = WebPGetFeatures(bytes, size, &features);
  if (status != VP8_STATUS_OK)
    return Status::ParseError("WebP: not a readable WebP image (libwebp status " + std::to_string(status) + ")");
  if (features.has_animation) return Status::Unsupported("WebP: an animated image; a texture must be a still one");
  G2P_RETURN_IF_ERROR(check_image_size("WebP", features.width, features.height));
  ImageU8 image(features.width, features.height, 4);
  const std::size_t stride = static_cast<std::size_t>(features.width) * 4;
  if (WebPDecodeRGBAInto(bytes, size, image.data(), stride * features.height, static_cast<int>(stride)) == nullptr)
    return Status::ParseError("WebP: the image data is damaged");
  return image;
}

}  // namespace g2p::detail
