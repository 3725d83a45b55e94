// Private: reading the numbers in BackendSettings (key = value strings).
#pragma once

#include <cmath>
#include <cstdlib>
#include <string>

namespace g2p::detail {

// The whole of `s` as a finite number; false for "", "1x", "nan", "inf".
inline bool parse_double(const std::string& s, double& out) {
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return end != s.c_str() && *end == '\0' && std::isfinite(out);
}

}  // namespace g2p::detail
