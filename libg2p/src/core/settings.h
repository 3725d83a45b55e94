// Private: settings that several backends share.
#pragma once

#include "g2p/settings.h"
#include "g2p/vlm.h"

namespace g2p::detail {

// The OpenAI-compatible client's settings, shared by every VLM backend: url,
// model, api_key_env, timeout, retries, backoff, max_response_bytes.
inline SettingsSpec& bind_openai(SettingsSpec& spec, OpenAiClientOptions& o) {
  return spec.text("url", o.base_url, "the server's OpenAI-compatible endpoint")
      .text("model", o.model, "the model the server runs")
      .text("api_key_env", o.api_key_env, "the environment variable holding the API key (the key is never logged)")
      .number("timeout", o.timeout_s, Range::above(0), "s", "per request")
      .integer("retries", o.retries, 0, 10, "", "further attempts after a 429 or 5xx answer")
      .number("backoff", o.backoff_s, Range::at_least(0), "s", "the first wait; doubles each retry (Retry-After wins)")
      .integer("max_response_bytes", o.max_response_bytes, std::size_t{1}, std::size_t{1000000000}, "bytes",
               "the largest answer read");
}

}  // namespace g2p::detail
