// The `vlm` refiner: the paper's critique-and-repair step. A vision-language
// model sees the rendered views, the same views colour-coded by the current
// labels, and the legend; it reasons (chain of thought, Wei et al. 2022) and
// ends with a JSON answer listing class corrections, which are validated and
// applied. The prompt is libg2p/data/refine_prompt.txt (setting prompt_file
// replaces it); {legend}, {summary} and {classes} are filled in.
//
// Anything that goes wrong with the model (unreachable, timeout, refusal, too
// large, malformed or partial JSON, unknown classes) loses nothing: the labels
// stand and RefineResult::notes says what happened.
//
// Settings: url, model (required), api_key_env, timeout, retries, backoff,
// max_response_bytes, prompt_file, max_views (default 6).
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/settings.h"
#include "g2p/segment.h"
#include "g2p/vlm.h"
#include "io/image_io.h"
#include "refine/backends.h"

namespace g2p {

extern const char* const kDefaultRefinePrompt;

namespace {

using nlohmann::json;

void replace_all(std::string& text, const std::string& key, const std::string& value) {
  for (std::size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + value.size()))
    text.replace(at, key.size(), value);
}

class VlmRefiner final : public Refiner {
 public:
  explicit VlmRefiner(std::shared_ptr<const VlmClient> client = nullptr)
      : client_(std::move(client)), injected_(client_ != nullptr) {}

  SettingsSpec settings() override {
    SettingsSpec spec("vlm");
    detail::bind_openai(spec, options_)
        .file("prompt_file", prompt_file_, "a prompt to use instead of the built-in one")
        .integer("max_views", max_views_, 1, 100, "", "views shown to the model")
        .check([this] { return connect(); });
    return spec;
  }

  Result<RefineResult> refine(const RefineInput& in) const override {
    if (in.mesh == nullptr || in.labels == nullptr || in.views == nullptr || in.table == nullptr)
      return Status::InvalidArgument("vlm: needs the mesh, labels, rendered views and the material table");
    if (client_ == nullptr) return Status::InvalidArgument("vlm: needs the setting model=NAME (and url=...)");
    const MaterialTable& table = *in.table;
    RefineResult result;
    result.labels = in.labels->label;

    Result<std::string> prompt = build_prompt(in);
    if (!prompt.ok()) return prompt.status();
    VlmRequest request;
    request.system = "You are an expert in materials and product design. Answer precisely.";
    request.prompt = *prompt;
    const std::size_t step = std::max<std::size_t>(1, (in.views->size() + max_views_ - 1) / max_views_);
    for (std::size_t v = 0; v < in.views->size(); v += step) {
      const View& view = (*in.views)[v];
      if (view.rgb.empty()) return Status::InvalidArgument("vlm: the views need RGB images");
      Result<std::string> rgb = detail::encode_png(view.rgb);
      Result<std::string> labels =
          detail::encode_png(colorize_labels(render_face_labels(view, in.labels->label).labels, table));
      if (!rgb.ok() || !labels.ok()) return Status::Internal("vlm: could not encode the views as PNG");
      request.images.push_back({*rgb, "View " + std::to_string(v) + ", rendered:"});
      request.images.push_back({*labels, "View " + std::to_string(v) + ", coloured by material class:"});
    }

    Result<std::string> answer = client_->complete(request);
    if (!answer.ok()) {
      result.notes.push_back("vlm: no correction applied, the labels stand: " + answer.status().to_string());
      result.fell_back = true;
      return result;
    }
    Result<std::string> text = extract_json_object(*answer);
    const json doc = text.ok() ? json::parse(*text, nullptr, /*allow_exceptions=*/false) : json();
    if (!text.ok() || doc.is_discarded() || !doc.is_object() || !doc.contains("corrections") ||
        !doc["corrections"].is_array()) {
      result.notes.push_back(
          "vlm: rejected the answer (no valid JSON object with a 'corrections' array); "
          "the labels stand");
      result.fell_back = true;
      return result;
    }
    if (doc.contains("object") && doc["object"].is_string())
      result.notes.push_back("vlm: the model sees " + doc["object"].get<std::string>());
    std::map<int, std::pair<int, std::string>> relabel;  // from -> (to, reason)
    for (const json& c : doc["corrections"]) {
      if (!c.is_object() || !c.contains("from") || !c.contains("to") || !c["from"].is_string() ||
          !c["to"].is_string()) {
        result.notes.push_back("vlm: rejected a correction without string 'from' and 'to': " + c.dump());
        continue;
      }
      const int from = table.find(c["from"].get<std::string>()), to = table.find(c["to"].get<std::string>());
      if (from == kUnknownLabel || to == kUnknownLabel) {
        result.notes.push_back("vlm: rejected a correction naming a class outside the vocabulary: " + c.dump());
        continue;
      }
      if (from == to) continue;
      const std::string reason = c.contains("reason") && c["reason"].is_string() ? c["reason"].get<std::string>() : "";
      relabel[from] = {to, reason};
    }
    // Corrections apply to the labels as they were (not chained: Wood->Metal, Metal->Wood swaps).
    for (std::size_t f = 0; f < result.labels.size(); ++f) {
      const auto it = relabel.find(in.labels->label[f]);
      if (it == relabel.end()) continue;
      result.labels[f] = it->second.first;
      result.changes.push_back({static_cast<int>(f), it->first, it->second.first,
                                "vlm: " + table[it->first].name + " -> " + table[it->second.first].name +
                                    (it->second.second.empty() ? "" : ": " + it->second.second)});
    }
    result.notes.push_back("vlm: applied " + std::to_string(relabel.size()) + " class corrections to " +
                           std::to_string(result.changes.size()) + " faces");
    return result;
  }

 private:
  // A client for the settings as they are (an injected one is kept). Without
  // a model there is nothing to ask: said when the pipeline is prepared, not
  // after rendering, segmenting and projecting.
  Status connect() {
    if (injected_) return Status::Ok();
    if (options_.model.empty())
      return Status::InvalidArgument(
          "vlm: needs the setting model=NAME (and url=URL unless the server listens on http://127.0.0.1:8080/v1)");
    Result<std::unique_ptr<VlmClient>> c = make_openai_client(options_);
    if (!c.ok()) return c.status();
    client_ = std::move(*c);
    return Status::Ok();
  }

  Result<std::string> build_prompt(const RefineInput& in) const {
    std::string prompt = kDefaultRefinePrompt;
    if (!prompt_file_.empty()) {
      std::ifstream file(prompt_file_, std::ios::binary);
      if (!file) return Status::NotFound("vlm: " + prompt_file_ + ": cannot open the prompt file");
      std::ostringstream text;
      text << file.rdbuf();
      prompt = text.str();
    }
    const MaterialTable& table = *in.table;
    std::vector<double> area(static_cast<std::size_t>(table.size()), 0.0);
    double total = 0.0;
    for (int f = 0; f < in.mesh->num_faces(); ++f) {
      const double a = face_area(*in.mesh, f);
      total += a;
      const int l = in.labels->label[static_cast<std::size_t>(f)];
      if (table.valid_label(l)) area[static_cast<std::size_t>(l)] += a;
    }
    std::string legend, summary, classes;
    char line[128];
    for (int c = 0; c < table.size(); ++c) {
      const auto& rgb = table[c].color;
      std::snprintf(line, sizeof(line), "- RGB(%d, %d, %d): %s\n", rgb[0], rgb[1], rgb[2], table[c].name.c_str());
      legend += line;
      classes += (classes.empty() ? "" : ", ") + table[c].name;
      if (area[static_cast<std::size_t>(c)] > 0.0) {
        std::snprintf(line, sizeof(line), "- %s: %.1f%%\n", table[c].name.c_str(),
                      100.0 * area[static_cast<std::size_t>(c)] / total);
        summary += line;
      }
    }
    replace_all(prompt, "{legend}", legend);
    replace_all(prompt, "{summary}", summary);
    replace_all(prompt, "{classes}", classes);
    return prompt;
  }

  std::shared_ptr<const VlmClient> client_;
  bool injected_ = false;  // a caller's client, kept whatever the settings say
  OpenAiClientOptions options_;
  std::string prompt_file_;
  int max_views_ = 6;
};

}  // namespace

std::unique_ptr<Refiner> make_vlm_refiner() { return std::make_unique<VlmRefiner>(); }

std::unique_ptr<Refiner> make_vlm_refiner(std::shared_ptr<const VlmClient> client) {
  return std::make_unique<VlmRefiner>(std::move(client));
}

}  // namespace g2p
