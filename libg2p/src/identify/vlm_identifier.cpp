// The "vlm" identifier: a vision-language model is shown a few rendered views
// and asked what the object is; its answer is read as a kind of the object
// table (the words it uses, matched like --object). A model that cannot be
// reached or answers nothing usable leaves the object unknown, with a warning.
#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "core/settings.h"
#include "identify/backends.h"
#include "io/image_io.h"

namespace g2p {
namespace {

using nlohmann::json;

class VlmIdentifier final : public Identifier {
 public:
  explicit VlmIdentifier(std::shared_ptr<const VlmClient> client = nullptr)
      : client_(std::move(client)), injected_(client_ != nullptr) {}

  SettingsSpec settings() override {
    SettingsSpec spec("identify vlm");
    detail::bind_openai(spec, options_)
        .integer("max_views", max_views_, 1, 20, "", "rendered views shown to the model")
        .check([this] { return connect(); });
    return spec;
  }

  Result<Identification> identify(const IdentifyInput& in) const override {
    Identification id;
    if (client_ == nullptr) return Status::InvalidArgument("identify vlm: needs the setting model=NAME");
    if (in.views == nullptr || in.views->empty()) {
      id.warnings.push_back("vlm: no rendered views to show; not identified");
      return id;
    }
    const ObjectTable& table = in.table != nullptr ? *in.table : ObjectTable::shipped();
    VlmRequest request;
    request.system = "You identify everyday objects in product renders. Answer precisely.";
    request.prompt =
        "These are renders of one 3D object from several sides. What everyday object is it? Answer with a JSON "
        "object {\"object\": \"<a short common noun phrase, e.g. 'office chair', 'refrigerator', 'sedan car'>\", "
        "\"confidence\": <0 to 1>}.";
    const std::size_t n = in.views->size();
    const std::size_t step =
        std::max<std::size_t>(1, (n + static_cast<std::size_t>(max_views_) - 1) / static_cast<std::size_t>(max_views_));
    for (std::size_t v = 0; v < n; v += step) {
      if ((*in.views)[v].rgb.empty()) continue;
      Result<std::string> png = detail::encode_png((*in.views)[v].rgb);
      if (!png.ok()) return Status::Internal("identify vlm: could not encode a view as PNG");
      request.images.push_back({*png, "View " + std::to_string(v) + ":"});
    }
    Result<std::string> answer = client_->complete(request);
    if (!answer.ok()) {
      id.warnings.push_back("vlm: no answer (" + answer.status().to_string() + "); not identified");
      return id;
    }
    Result<std::string> text = extract_json_object(*answer);
    const json doc = text.ok() ? json::parse(*text, nullptr, /*allow_exceptions=*/false) : json();
    if (!text.ok() || doc.is_discarded() || !doc.is_object() || !doc.value("object", json()).is_string()) {
      id.warnings.push_back("vlm: the answer held no JSON object with an 'object' text; not identified");
      return id;
    }
    const std::string words = doc["object"].get<std::string>();
    double confidence = doc.value("confidence", json(0.7)).is_number() ? doc.value("confidence", 0.7) : 0.7;
    if (!std::isfinite(confidence)) confidence = 0.7;
    confidence = std::clamp(confidence, 0.0, 0.95);
    const std::vector<TextMatch> m = table.match(words);
    if (m.empty()) {
      id.notes.push_back("vlm: the model sees '" + words + "', which names no kind of the object table");
      return id;
    }
    id.candidates.push_back({table.kinds()[static_cast<std::size_t>(m.front().kind)].name, confidence, "vlm",
                             "the model's words '" + words + "'"});
    return id;
  }

 private:
  // A client for the settings as they are (an injected one is kept).
  Status connect() {
    if (injected_) return Status::Ok();
    if (options_.model.empty())
      return Status::InvalidArgument(
          "identify vlm: needs the setting model=NAME (and url=URL unless the server listens on "
          "http://127.0.0.1:8080/v1)");
    Result<std::unique_ptr<VlmClient>> c = make_openai_client(options_);
    if (!c.ok()) return c.status();
    client_ = std::move(*c);
    return Status::Ok();
  }

  OpenAiClientOptions options_;
  std::shared_ptr<const VlmClient> client_;
  bool injected_ = false;
  int max_views_ = 4;
};

}  // namespace

std::unique_ptr<Identifier> detail::make_vlm_identifier() { return std::make_unique<VlmIdentifier>(); }

std::unique_ptr<Identifier> make_vlm_identifier(std::shared_ptr<const VlmClient> client) {
  return std::make_unique<VlmIdentifier>(std::move(client));
}

}  // namespace g2p
