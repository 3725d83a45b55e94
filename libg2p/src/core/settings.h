// Private: reading the numbers in BackendSettings (key = value strings).
#pragma once

#include <cmath>
#include <cstdlib>
#include <string>

#include "g2p/vlm.h"

namespace g2p::detail {

// The whole of `s` as a finite number; false for "", "1x", "nan", "inf".
inline bool parse_double(const std::string& s, double& out) {
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return end != s.c_str() && *end == '\0' && std::isfinite(out);
}

// The OpenAI-compatible client's settings shared by every VLM backend: url,
// model, api_key_env, timeout (s, > 0), retries (0..10), backoff (s, >= 0),
// max_response_bytes (1..1e9). False if `key` is not one of them or the value
// is bad.
inline bool set_openai_option(OpenAiClientOptions& o, const std::string& key, const std::string& value) {
  double v = 0;
  const bool number = parse_double(value, v);
  const bool count = number && v >= 0 && v == std::floor(v);
  if (key == "url")
    o.base_url = value;
  else if (key == "model")
    o.model = value;
  else if (key == "api_key_env")
    o.api_key_env = value;
  else if (key == "timeout" && number && v > 0)
    o.timeout_s = v;
  else if (key == "retries" && count && v <= 10)
    o.retries = static_cast<int>(v);
  else if (key == "backoff" && number && v >= 0)
    o.backoff_s = v;
  else if (key == "max_response_bytes" && count && v >= 1 && v <= 1e9)
    o.max_response_bytes = static_cast<std::size_t>(v);
  else
    return false;
  return true;
}
inline constexpr const char* kOpenAiOptionKeys =
    "url, model, api_key_env, timeout, retries, backoff, max_response_bytes";

}  // namespace g2p::detail
