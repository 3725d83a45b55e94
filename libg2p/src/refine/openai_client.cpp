// VlmClient over the OpenAI chat-completions API with libcurl.
#include <curl/curl.h>

#include <chrono>
#include <cstdlib>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "core/ascii.h"
#include "core/json_text.h"
#include "core/utf8.h"
#include "g2p/vlm.h"

namespace g2p {

VlmClient::~VlmClient() = default;

std::string base64_encode(const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += {kAlphabet[v >> 18], kAlphabet[(v >> 12) & 63], kAlphabet[(v >> 6) & 63], kAlphabet[v & 63]};
  }
  if (i + 1 == bytes.size()) {
    const unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    out += {kAlphabet[v >> 18], kAlphabet[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == bytes.size()) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8);
    out += {kAlphabet[v >> 18], kAlphabet[(v >> 12) & 63], kAlphabet[(v >> 6) & 63], '='};
  }
  return out;
}

Result<std::string> extract_json_object(const std::string& answer) {
  const std::string fence = "```json";
  const std::size_t f = answer.rfind(fence);
  if (f != std::string::npos) {
    const std::size_t start = f + fence.size();
    const std::size_t end = answer.find("```", start);
    if (end != std::string::npos) return answer.substr(start, end - start);
  }
  // The last balanced {...}, scanning back from the last '}' (strings with
  // braces inside are rare in these answers and then fail JSON parsing).
  const std::size_t close = answer.rfind('}');
  if (close == std::string::npos) return Status::ParseError("the answer holds no JSON object");
  int depth = 0;
  for (std::size_t i = close + 1; i-- > 0;) {
    if (answer[i] == '}')
      ++depth;
    else if (answer[i] == '{' && --depth == 0)
      return answer.substr(i, close - i + 1);
  }
  return Status::ParseError("the answer's JSON object is not balanced");
}

namespace {

struct Body {
  std::string data;
  std::size_t cap;
  bool overflow = false;
};

std::size_t on_data(char* ptr, std::size_t size, std::size_t n, void* user) {
  auto* body = static_cast<Body*>(user);
  if (body->data.size() + size * n > body->cap) {
    body->overflow = true;
    return 0;  // aborts the transfer
  }
  body->data.append(ptr, size * n);
  return size * n;
}

std::size_t on_header(char* ptr, std::size_t size, std::size_t n, void* user) {
  const std::string line(ptr, size * n);
  const std::string key = "retry-after:";
  if (line.size() > key.size()) {
    if (detail::lower_case(line.substr(0, key.size())) == key)
      *static_cast<double*>(user) = std::atof(line.c_str() + key.size());
  }
  return size * n;
}

void init_curl_once() {
  static std::once_flag once;
  std::call_once(once, [] { curl_global_init(CURL_GLOBAL_DEFAULT); });
}

// The secrets a URL carries: its user information and each query value.
std::vector<std::string> url_secrets(const std::string& url) {
  std::vector<std::string> out;
  const std::size_t scheme = url.find("://");
  const std::size_t host = scheme == std::string::npos ? 0 : scheme + 3;
  const std::size_t path = url.find_first_of("/?#", host);
  const std::size_t at = url.rfind('@', path == std::string::npos ? std::string::npos : path);
  if (at != std::string::npos && at > host) {
    const std::string info = url.substr(host, at - host);
    out.push_back(info);
    if (const std::size_t colon = info.find(':'); colon != std::string::npos) out.push_back(info.substr(colon + 1));
  }
  for (std::size_t eq = url.find('=', host); eq != std::string::npos; eq = url.find('=', eq + 1))
    out.push_back(url.substr(eq + 1, url.find_first_of("&#", eq + 1) - eq - 1));
  return out;
}

// The start of a server's error body for a message: every secret (and any
// "Bearer" token) replaced by ***, at most 300 bytes cut where a UTF-8
// character begins, and bytes that are not UTF-8 read as Latin-1 (a proxy's
// error page), so that the message can go into JSON and logs.
std::string server_excerpt(std::string body, const std::vector<std::string>& secrets) {
  for (const std::string& secret : secrets) {
    if (secret.size() < 4) continue;  // too short to search for without mangling the text
    for (std::size_t at = body.find(secret); at != std::string::npos; at = body.find(secret, at + 3))
      body.replace(at, secret.size(), "***");
  }
  for (std::size_t at = body.find("Bearer "); at != std::string::npos; at = body.find("Bearer ", at + 7)) {
    const std::size_t end = body.find_first_of(" \t\r\n\"',;}", at + 7);
    body.replace(at + 7, (end == std::string::npos ? body.size() : end) - at - 7, "***");
  }
  const std::size_t limit = 300;
  if (body.size() > limit) {
    std::size_t cut = limit;
    while (cut > 0 && (static_cast<unsigned char>(body[cut]) & 0xC0) == 0x80) --cut;
    body = body.substr(0, cut) + "...";
  }
  return detail::utf8_name(body);
}

class OpenAiClient final : public VlmClient {
 public:
  explicit OpenAiClient(OpenAiClientOptions o) : o_(std::move(o)) {}

  Result<std::string> complete(const VlmRequest& request) const override {
    using nlohmann::json;
    json content = json::array();
    content.push_back({{"type", "text"}, {"text", request.prompt}});
    for (const VlmImage& image : request.images) {
      if (!image.caption.empty()) content.push_back({{"type", "text"}, {"text", image.caption}});
      content.push_back(
          {{"type", "image_url"}, {"image_url", {{"url", "data:image/png;base64," + base64_encode(image.png)}}}});
    }
    json messages = json::array();
    if (!request.system.empty()) messages.push_back({{"role", "system"}, {"content", request.system}});
    messages.push_back({{"role", "user"}, {"content", content}});
    const std::string payload =
        detail::json_text(json{{"model", o_.model}, {"temperature", o_.temperature}, {"messages", messages}});
    // The endpoint's path goes before any query string (`.../v1?key=K` ->
    // `.../v1/chat/completions?key=K`); messages show the URL redacted.
    const std::size_t query = o_.base_url.find_first_of("?#");
    std::string base = o_.base_url.substr(0, query);
    const std::string tail = query == std::string::npos ? "" : o_.base_url.substr(query);
    if (base.empty() || base.back() != '/') base += '/';
    const std::string url_with_secrets = base + "chat/completions" + tail;
    const std::string url = redact_url(url_with_secrets);

    // What a server may echo back in an error (the key, the URL's own
    // credentials), never to be repeated in a message.
    std::vector<std::string> secrets = url_secrets(url_with_secrets);
    if (const char* key = o_.api_key_env.empty() ? nullptr : std::getenv(o_.api_key_env.c_str()); key != nullptr)
      secrets.emplace_back(key);

    double wait_s = o_.backoff_s;  // before the next attempt: backoff, 2 backoff, 4 backoff... or Retry-After
    std::string last_error;
    for (int attempt = 0; attempt <= o_.retries; ++attempt) {
      if (attempt > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait_s));
      const double next_wait = o_.backoff_s * static_cast<double>(1 << std::min(attempt + 1, 20));
      CURL* curl = curl_easy_init();
      if (curl == nullptr) return Status::Internal("vlm: libcurl could not start");
      Body body{{}, o_.max_response_bytes};
      double retry_after = -1.0;
      curl_slist* headers = curl_slist_append(nullptr, "Content-Type: application/json");
      if (const char* key = o_.api_key_env.empty() ? nullptr : std::getenv(o_.api_key_env.c_str());
          key != nullptr && *key != '\0') {
        const std::string auth = std::string("Authorization: Bearer ") + key;
        headers = curl_slist_append(headers, auth.c_str());  // copied by curl; never logged
      }
      curl_easy_setopt(curl, CURLOPT_URL, url_with_secrets.c_str());
      curl_easy_setopt(curl, CURLOPT_HTTPHEADER, headers);
      curl_easy_setopt(curl, CURLOPT_POSTFIELDS, payload.c_str());
      curl_easy_setopt(curl, CURLOPT_POSTFIELDSIZE_LARGE, static_cast<curl_off_t>(payload.size()));
      curl_easy_setopt(curl, CURLOPT_WRITEFUNCTION, &on_data);
      curl_easy_setopt(curl, CURLOPT_WRITEDATA, &body);
      curl_easy_setopt(curl, CURLOPT_HEADERFUNCTION, &on_header);
      curl_easy_setopt(curl, CURLOPT_HEADERDATA, &retry_after);
      curl_easy_setopt(curl, CURLOPT_TIMEOUT_MS, static_cast<long>(o_.timeout_s * 1000.0));
      curl_easy_setopt(curl, CURLOPT_CONNECTTIMEOUT_MS, static_cast<long>(std::min(o_.timeout_s, 30.0) * 1000.0));
      curl_easy_setopt(curl, CURLOPT_NOSIGNAL, 1L);
      const CURLcode code = curl_easy_perform(curl);
      long status = 0;
      curl_easy_getinfo(curl, CURLINFO_RESPONSE_CODE, &status);
      curl_slist_free_all(headers);
      curl_easy_cleanup(curl);

      if (body.overflow)
        return Status::Unavailable("vlm: the answer exceeds " + std::to_string(o_.max_response_bytes) + " bytes");
      if (code == CURLE_OPERATION_TIMEDOUT)
        return Status::Unavailable("vlm: no answer from " + url + " within " + std::to_string(o_.timeout_s) + " s");
      if (code != CURLE_OK) {
        last_error = std::string("vlm: ") + url + ": " + curl_easy_strerror(code);
        if (code == CURLE_COULDNT_CONNECT || code == CURLE_COULDNT_RESOLVE_HOST) return Status::Unavailable(last_error);
      } else if (status == 429 || status >= 500) {
        last_error = "vlm: " + url + " answered HTTP " + std::to_string(status);
      } else if (status != 200) {
        return Status::Unavailable("vlm: " + url + " answered HTTP " + std::to_string(status) + ": " +
                                   server_excerpt(body.data, secrets));
      } else {
        const json doc = json::parse(body.data, nullptr, /*allow_exceptions=*/false);
        if (doc.is_discarded() || !doc.contains("choices") || !doc["choices"].is_array() || doc["choices"].empty())
          return Status::ParseError("vlm: the server's answer is not a chat completion");
        const json& message = doc["choices"][0].value("message", json::object());
        if (!message.contains("content") || !message["content"].is_string())
          return Status::ParseError("vlm: the chat completion has no text content");
        return message["content"].get<std::string>();
      }
      wait_s = retry_after > 0.0 ? std::min(retry_after, 60.0) : next_wait;
    }
    return Status::Unavailable(last_error + " (gave up after " + std::to_string(o_.retries + 1) + " attempts)");
  }

 private:
  OpenAiClientOptions o_;
};

}  // namespace

std::string redact_url(const std::string& url) {
  std::string out = url;
  const std::size_t scheme = out.find("://");
  const std::size_t host = scheme == std::string::npos ? 0 : scheme + 3;
  const std::size_t path = out.find_first_of("/?#", host);
  const std::size_t at = out.rfind('@', path == std::string::npos ? std::string::npos : path);
  if (at != std::string::npos && at >= host) out.replace(host, at - host, "***");
  // A fragment never reaches the server but can hold a token (`#access_token=`).
  if (const std::size_t hash = out.find('#', host); hash != std::string::npos && hash + 1 < out.size())
    out = out.substr(0, hash + 1) + "***";
  const std::size_t query = out.find('?');
  if (query == std::string::npos) return out;
  const std::size_t fragment = out.find('#', query);
  std::string redacted = out.substr(0, query + 1);
  const std::string params =
      out.substr(query + 1, fragment == std::string::npos ? std::string::npos : fragment - query - 1);
  std::size_t start = 0;
  while (start <= params.size()) {
    const std::size_t end = std::min(params.find('&', start), params.size());
    const std::string param = params.substr(start, end - start);
    const std::size_t eq = param.find('=');
    redacted += eq == std::string::npos ? param : param.substr(0, eq + 1) + "***";
    if (end < params.size()) redacted += '&';
    start = end + 1;
  }
  if (fragment != std::string::npos) redacted += out.substr(fragment);
  return redacted;
}

Result<std::unique_ptr<VlmClient>> make_openai_client(const OpenAiClientOptions& options) {
  if (options.model.empty()) return Status::InvalidArgument("vlm: a model name is needed");
  if (options.base_url.rfind("http://", 0) != 0 && options.base_url.rfind("https://", 0) != 0)
    return Status::InvalidArgument("vlm: base URL must start with http:// or https://, got '" +
                                   redact_url(options.base_url) + "'");
  if (!(options.timeout_s >= 0.001 && options.timeout_s <= 86400.0) || options.retries < 0 || options.retries > 10 ||
      options.max_response_bytes == 0 || !(options.backoff_s >= 0.0 && options.backoff_s <= 3600.0))
    return Status::InvalidArgument(
        "vlm: need 0.001 <= timeout <= 86400 s, retries in 0..10, backoff in [0, 3600] s, max response > 0 bytes");
  init_curl_once();
  return std::unique_ptr<VlmClient>(std::make_unique<OpenAiClient>(options));
}

}  // namespace g2p
