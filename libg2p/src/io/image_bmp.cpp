// Windows BMP, read and written here (the format is a header and rows): 1-,
// 4- and 8-bit palettes, 16-bit 5-5-5 and bit fields, 24- and 32-bit, bottom-up
// or top-down; run-length compressed files are refused by name. Written as
// 24-bit (RGB, grey) or 32-bit with alpha (RGBA, BITMAPV4HEADER).
#include <vector>

#include "io/image_codecs.h"

namespace g2p::detail {
namespace {

std::uint32_t u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}
std::uint16_t u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | p[1] << 8); }

// A bit-field channel of `pixel` scaled to 0..255; `mask` 0 gives `none`.
std::uint8_t channel(std::uint32_t pixel, std::uint32_t mask, std::uint8_t none) {
  if (mask == 0) return none;
  int shift = 0;
  while (((mask >> shift) & 1u) == 0) ++shift;
  const std::uint64_t max = mask >> shift;  // 64 bits: a 32-bit field times 255 overflows 32
  return static_cast<std::uint8_t>((static_cast<std::uint64_t>((pixel & mask) >> shift) * 255 + max / 2) / max);
}

void put_u32(std::string& s, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void put_u16(std::string& s, std::uint16_t v) {
  s.push_back(static_cast<char>(v & 0xFF));
  s.push_back(static_cast<char>(v >> 8));
}

}  // namespace

Result<ImageU8> decode_bmp(const std::uint8_t* b, std::size_t size) {
  auto bad = [](const std::string& what) { return Status::ParseError("BMP: " + what); };
  if (size < 26 || b[0] != 'B' || b[1] != 'M') return bad("not a BMP file");
  const std::uint32_t data_at = u32(b + 10), header = u32(b + 14);
  if (header < 12 || 14 + static_cast<std::size_t>(header) > size) return bad("the header is cut short");
  long long width = 0, height = 0;
  int bits = 0;
  std::uint32_t compression = 0, colours = 0, masks[4] = {0, 0, 0, 0};
  std::size_t palette_at = 14 + header, palette_entry = 4;
  if (header == 12) {  // OS/2 BITMAPCOREHEADER
    width = u16(b + 18), height = static_cast<std::int16_t>(u16(b + 20)), bits = u16(b + 24);
    palette_entry = 3;
  } else {
    if (size < 54) return bad("the header is cut short");
    width = static_cast<std::int32_t>(u32(b + 18)), height = static_cast<std::int32_t>(u32(b + 22));
    bits = u16(b + 28), compression = u32(b + 30), colours = u32(b + 46);
    if (compression == 3 || compression == 6) {  // BI_BITFIELDS, BI_ALPHABITFIELDS
      const std::size_t at = header >= 52 ? 54 : 14 + header;
      const int n = compression == 6 || header >= 56 ? 4 : 3;
      if (at + 4 * static_cast<std::size_t>(n) > size) return bad("the bit fields are cut short");
      for (int i = 0; i < n; ++i) masks[i] = u32(b + at + 4 * i);
      if (header < 52) palette_at += 4 * static_cast<std::size_t>(n);
    }
  }
  if (compression == 1 || compression == 2) return Status::Unsupported("BMP: run-length compressed files are not read");
  if (compression == 4 || compression == 5) return Status::Unsupported("BMP: embedded JPEG or PNG data is not read");
  if (compression != 0 && compression != 3 && compression != 6)
    return bad("unknown compression " + std::to_string(compression));
  const bool top_down = height < 0;
  if (top_down) height = -height;
  G2P_RETURN_IF_ERROR(check_image_size("BMP", width, height));
  if (bits != 1 && bits != 4 && bits != 8 && bits != 16 && bits != 24 && bits != 32)
    return bad(std::to_string(bits) + " bits a pixel");
  if ((compression == 3 || compression == 6) && bits != 16 && bits != 32) return bad("bit fields need 16 or 32 bits");
  if (compression == 0 && bits == 16) masks[0] = 0x7C00, masks[1] = 0x03E0, masks[2] = 0x001F;  // 5-5-5
  std::vector<std::uint8_t> palette;                                                            // RGB triples
  if (bits <= 8) {
    const std::size_t n = colours != 0 && colours <= (1u << bits) ? colours : (1u << bits);
    if (palette_at + n * palette_entry > size) return bad("the palette is cut short");
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint8_t* e = b + palette_at + i * palette_entry;
      palette.insert(palette.end(), {e[2], e[1], e[0]});
    }
  }
  const std::size_t stride = ((static_cast<std::size_t>(width) * bits + 31) / 32) * 4;
  if (data_at > size || stride * static_cast<std::size_t>(height) > size - data_at)
    return bad("the pixel data is cut short");
  // 32-bit BI_RGB: the fourth byte is alpha only if some pixel uses it.
  bool alpha32 = false;
  if (bits == 32 && compression == 0)
    for (long long y = 0; y < height && !alpha32; ++y)
      for (long long x = 0; x < width && !alpha32; ++x) alpha32 = b[data_at + y * stride + 4 * x + 3] != 0;
  ImageU8 image(static_cast<int>(width), static_cast<int>(height), 4);
  for (long long y = 0; y < height; ++y) {
    const std::uint8_t* row = b + data_at + static_cast<std::size_t>(top_down ? y : height - 1 - y) * stride;
    std::uint8_t* out = image.data() + static_cast<std::size_t>(y) * width * 4;
    for (long long x = 0; x < width; ++x, out += 4) {
      out[3] = 255;
      if (bits <= 8) {
        const std::size_t bit = static_cast<std::size_t>(x) * bits;
        const unsigned index = (row[bit / 8] >> (8 - bits - bit % 8)) & ((1u << bits) - 1);
        if (3 * index + 2 >= palette.size()) return bad("a pixel names a colour beyond the palette");
        out[0] = palette[3 * index], out[1] = palette[3 * index + 1], out[2] = palette[3 * index + 2];
      } else if (bits == 24) {
        out[0] = row[3 * x + 2], out[1] = row[3 * x + 1], out[2] = row[3 * x];
      } else if (bits == 32 && compression == 0) {
        out[0] = row[4 * x + 2], out[1] = row[4 * x + 1], out[2] = row[4 * x];
        if (alpha32) out[3] = row[4 * x + 3];
      } else {
        const std::uint32_t p = bits == 16 ? u16(row + 2 * x) : u32(row + 4 * x);
        out[0] = channel(p, masks[0], 0), out[1] = channel(p, masks[1], 0), out[2] = channel(p, masks[2], 0);
        out[3] = channel(p, masks[3], 255);
      }
    }
  }
  return image;
}

Result<std::string> encode_bmp(const ImageU8& image) {
  const int c = image.channels();
  if (image.empty() || (c != 1 && c != 3 && c != 4))
    return Status::InvalidArgument("BMP: cannot encode an image with " + std::to_string(c) + " channels");
  const int w = image.width(), h = image.height();
  const bool alpha = c == 4;
  const std::uint32_t header = alpha ? 108 : 40;  // BITMAPV4HEADER carries the alpha mask
  const std::size_t stride = alpha ? static_cast<std::size_t>(w) * 4 : ((static_cast<std::size_t>(w) * 3 + 3) / 4) * 4;
  const std::size_t data_at = 14 + header;
  std::string s;
  s.reserve(data_at + stride * h);
  s += "BM";
  put_u32(s, static_cast<std::uint32_t>(data_at + stride * h));
  put_u32(s, 0);
  put_u32(s, static_cast<std::uint32_t>(data_at));
  put_u32(s, header);
  put_u32(s, static_cast<std::uint32_t>(w));
  put_u32(s, static_cast<std::uint32_t>(h));  // bottom-up
  put_u16(s, 1);
  put_u16(s, alpha ? 32 : 24);
  put_u32(s, alpha ? 3 : 0);  // BI_BITFIELDS with an alpha mask, or BI_RGB
  put_u32(s, static_cast<std::uint32_t>(stride * h));
  put_u32(s, 2835);  // 72 dpi
  put_u32(s, 2835);
  put_u32(s, 0);
  put_u32(s, 0);
  if (alpha) {
    for (std::uint32_t m : {0x00FF0000u, 0x0000FF00u, 0x000000FFu, 0xFF000000u}) put_u32(s, m);
    put_u32(s, 0x73524742);  // 'sRGB'
    s.append(48, '\0');      // endpoints and gamma, unused with sRGB
  }
  for (int y = h - 1; y >= 0; --y) {
    const std::uint8_t* p = image.data() + static_cast<std::size_t>(y) * w * c;
    const std::size_t start = s.size();
    for (int x = 0; x < w; ++x, p += c) {
      const std::uint8_t r = p[0], g = c == 1 ? p[0] : p[1], bl = c == 1 ? p[0] : p[2];
      s.push_back(static_cast<char>(bl));
      s.push_back(static_cast<char>(g));
      s.push_back(static_cast<char>(r));
      if (alpha) s.push_back(static_cast<char>(p[3]));
    }
    s.append(stride - (s.size() - start), '\0');
  }
  return s;
}

}  // namespace g2p::detail
