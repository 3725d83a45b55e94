// Private: numbers appended to text as printf writes them ("%d", "%.Ng",
// "%.Nf"), without printf's cost (std::to_chars: no locale, no format
// parsing). The files of a million-triangle run hold tens of millions.
#pragma once

#include <charconv>
#include <string>

namespace g2p::detail {

// As "%d" / "%lld".
inline void append_integer(std::string& out, long long value) {
  char text[24];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  out.append(text, end);
}

// As "%.<digits>g".
inline void append_general(std::string& out, double value, int digits) {
  char text[64];
  const auto end = std::to_chars(text, text + sizeof text, value, std::chars_format::general, digits).ptr;
  out.append(text, end);
}

// The shortest text that reads back as the same float (std::to_chars'
// round-trip guarantee): at most 9 significant digits, usually fewer.
inline void append_shortest(std::string& out, float value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  out.append(text, end);
}

// As "%.<decimals>f", for values below 1e30.
inline void append_fixed(std::string& out, double value, int decimals) {
  char text[64];
  const auto result = std::to_chars(text, text + sizeof text, value, std::chars_format::fixed, decimals);
  if (result.ec == std::errc())
    out.append(text, result.ptr);
  else
    append_general(out, value, 17);  // too long for the buffer: never a truncated number
}

}  // namespace g2p::detail
