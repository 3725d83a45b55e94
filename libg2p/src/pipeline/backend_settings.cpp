// describe_backend_settings: every stage's registry asked for a backend's
// settings (`g2p run --settings NAME`, Python's g2p.backend_settings).
#include <functional>

#include "g2p/complete.h"
#include "g2p/decompose.h"
#include "g2p/identify.h"
#include "g2p/pipeline.h"
#include "g2p/properties.h"
#include "g2p/refine.h"
#include "g2p/segment.h"

namespace g2p {
namespace {

struct StageRegistry {
  Stage stage;
  std::function<std::vector<std::string>()> names;
  std::function<Result<std::vector<SettingInfo>>(const std::string&)> settings;
};

template <typename Interface>
StageRegistry entry(Stage stage, Registry<Interface>& r) {
  return {stage, [&r] { return r.names(); }, [&r](const std::string& n) { return r.settings(n); }};
}

}  // namespace

Result<std::vector<BackendSettingsInfo>> describe_backend_settings(const std::string& name) {
  const StageRegistry stages[] = {
      entry(Stage::kIdentify, identifier_registry()),  entry(Stage::kSegment, segmenter_registry()),
      entry(Stage::kRefine, refiner_registry()),       entry(Stage::kComplete, completer_registry()),
      entry(Stage::kProperties, estimator_registry()), entry(Stage::kDecompose, decomposer_registry())};
  std::string stage_word, backend = name;
  if (const std::size_t colon = name.find(':'); colon != std::string::npos) {
    stage_word = name.substr(0, colon);
    backend = name.substr(colon + 1);
  }
  std::vector<BackendSettingsInfo> out;
  std::string known;
  bool stage_known = stage_word.empty();
  for (const StageRegistry& s : stages) {
    if (!stage_word.empty() && stage_word != to_string(s.stage)) continue;
    stage_known = true;
    for (const std::string& n : s.names()) {
      known += (known.empty() ? "" : ", ") + std::string(to_string(s.stage)) + ":" + n;
      if (backend != "all" && n != backend) continue;
      Result<std::vector<SettingInfo>> settings = s.settings(n);
      if (!settings.ok()) return settings.status();
      out.push_back({s.stage, n, std::move(*settings)});
    }
  }
  if (!stage_known)
    return Status::NotFound("no stage named '" + stage_word +
                            "' (stages with backends: identify, segment, refine, complete, properties, decompose)");
  if (out.empty()) return Status::NotFound("no backend named '" + name + "' (known: " + known + ")");
  return out;
}

}  // namespace g2p
