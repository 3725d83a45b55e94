// VlmClient: a vision-language model behind any OpenAI-compatible
// chat-completions API (Gemini's OpenAI endpoint, vLLM, Ollama, the llama.cpp
// server, ...). The refine stage asks it to critique labels; the properties
// stage will ask it for densities. docs/vlm.md shows how to point it at a
// local or hosted server.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

struct VlmImage {
  std::string png;      // PNG bytes
  std::string caption;  // text sent just before the image ("view 3, labels")
};

struct VlmRequest {
  std::string system;  // the system message
  std::string prompt;  // the user message's text
  std::vector<VlmImage> images;
};

class G2P_API VlmClient {
 public:
  virtual ~VlmClient();
  // The model's answer text. Errors name what failed (HTTP status, timeout,
  // size cap) and never contain the API key.
  virtual Result<std::string> complete(const VlmRequest& request) const = 0;
};

struct OpenAiClientOptions {
  std::string base_url = "http://127.0.0.1:8080/v1";  // POST {base_url}/chat/completions
  std::string model;                                  // required, e.g. "gemini-2.5-pro", "qwen2.5-vl"
  std::string api_key_env = "G2P_VLM_API_KEY";        // environment variable holding the key; unset = no key
  double timeout_s = 120.0;                           // per attempt
  int retries = 3;                                    // further attempts after a 429 or 5xx answer
  double backoff_s = 2.0;                             // first wait; doubles each retry (Retry-After wins)
  std::size_t max_response_bytes = 4u << 20;          // larger answers are refused
  double temperature = 0.0;
};

// A client for an OpenAI-compatible server (libcurl). The key is read from
// the environment at each request and sent as "Authorization: Bearer ...";
// it is never logged or written anywhere.
G2P_API Result<std::unique_ptr<VlmClient>> make_openai_client(const OpenAiClientOptions& options);

// The JSON object in a model's answer: the last ```json fenced block, or else
// the last balanced {...} in the text (models reason first, then answer).
G2P_API Result<std::string> extract_json_object(const std::string& answer);

// Base64 (RFC 4648), for data URLs.
G2P_API std::string base64_encode(const std::string& bytes);

// A URL as it may be shown or written: user and password (`user:pw@`) and
// every query value (`?key=...`) replaced by `***`. Messages, run.json,
// refine.json and summary.html carry only this form.
G2P_API std::string redact_url(const std::string& url);

}  // namespace g2p
