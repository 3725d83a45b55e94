#include "core/srgb.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace g2p::detail {

float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

float linear_to_srgb(float c) { return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.f / 2.4f) - 0.055f; }

std::uint8_t linear_to_srgb8(float c) {
  // 4096-entry table: the inverse transfer function is too slow per pixel.
  static const std::array<std::uint8_t, 4097> lut = [] {
    std::array<std::uint8_t, 4097> t{};
    for (int i = 0; i <= 4096; ++i)
      t[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(std::lround(255.f * linear_to_srgb(i / 4096.f)));
    return t;
  }();
  if (!(c > 0.f)) return 0;  // also NaN
  return lut[static_cast<std::size_t>(std::min(c, 1.f) * 4096.f + 0.5f)];
}

}  // namespace g2p::detail
