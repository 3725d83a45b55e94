// Private: the sRGB transfer function (IEC 61966-2-1), for every stage that
// turns 8-bit colour into linear light or back (import, render, the summary).
#pragma once

#include <cstdint>

namespace g2p::detail {

// sRGB <-> linear, both in [0, 1].
float srgb_to_linear(float c);
float linear_to_srgb(float c);
std::uint8_t linear_to_srgb8(float c);  // clamps to [0, 1] first

}  // namespace g2p::detail
