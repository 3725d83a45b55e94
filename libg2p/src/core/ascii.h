// Private: ASCII case folding, the one copy the readers of names, options and
// file extensions share (the C locale's tolower: other bytes unchanged).
#pragma once

#include <cctype>
#include <string>

namespace g2p::detail {

inline std::string lower_case(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace g2p::detail
