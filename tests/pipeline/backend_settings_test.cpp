// Every backend's settings as described (settings.h) against what its
// configure() does: the description's defaults are accepted back, a value
// outside the described range is refused, and a refused call changes nothing.
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <set>
#include <string>

#include "g2p/complete.h"
#include "g2p/decompose.h"
#include "g2p/identify.h"
#include "g2p/pipeline.h"
#include "g2p/properties.h"
#include "g2p/refine.h"
#include "g2p/segment.h"

namespace g2p {
namespace {

// A fresh backend of `stage` called `name`, as an object that can be
// configured and described.
struct Backend {
  std::function<Status(const BackendSettings&)> configure;
  std::function<std::vector<SettingInfo>()> info;
  std::shared_ptr<void> keep;
};

template <typename Interface>
Backend make(Registry<Interface>& r, const std::string& name) {
  Result<std::unique_ptr<Interface>> made = r.create(name);
  EXPECT_TRUE(made.ok()) << made.status().message();
  std::shared_ptr<Interface> b(std::move(*made));
  return {[b](const BackendSettings& s) { return b->configure(s); }, [b] { return b->settings().info(); }, b};
}

Backend make(Stage stage, const std::string& name) {
  switch (stage) {
    case Stage::kIdentify: return make(identifier_registry(), name);
    case Stage::kSegment: return make(segmenter_registry(), name);
    case Stage::kRefine: return make(refiner_registry(), name);
    case Stage::kComplete: return make(completer_registry(), name);
    case Stage::kProperties: return make(estimator_registry(), name);
    default: return make(decomposer_registry(), name);
  }
}

// Settings a backend cannot run without: its configure() refuses the
// defaults and says which setting it needs.
const std::set<std::string> kRequired = {"refine:vlm/model", "identify:vlm/model", "segment:oracle/labels"};

std::string id(const BackendSettingsInfo& b) { return std::string(to_string(b.stage)) + ":" + b.backend; }

std::vector<BackendSettingsInfo> all_backends() {
  Result<std::vector<BackendSettingsInfo>> all = describe_backend_settings("all");
  EXPECT_TRUE(all.ok()) << all.status().message();
  return all.ok() ? *all : std::vector<BackendSettingsInfo>{};
}

TEST(BackendSettings, EveryRegisteredBackendIsDescribed) {
  const std::vector<BackendSettingsInfo> all = all_backends();
  std::size_t expected = identifier_registry().names().size() + segmenter_registry().names().size() +
                         refiner_registry().names().size() + completer_registry().names().size() +
                         estimator_registry().names().size() + decomposer_registry().names().size();
  EXPECT_EQ(all.size(), expected);
  std::size_t settings = 0;
  for (const BackendSettingsInfo& b : all) {
    std::set<std::string> keys;
    for (const SettingInfo& i : b.settings) {
      EXPECT_TRUE(keys.insert(i.key).second) << id(b) << " describes " << i.key << " twice";
      EXPECT_FALSE(i.help.empty()) << id(b) << "/" << i.key;
      EXPECT_TRUE(i.type == "number" || i.type == "integer" || i.type == "on|off" || i.type == "choice" ||
                  i.type == "text" || i.type == "file")
          << id(b) << "/" << i.key << ": " << i.type;
      ++settings;
    }
  }
  EXPECT_GT(settings, 50u);  // hybrid alone has 9
}

TEST(BackendSettings, TheDescribedDefaultsAreAcceptedBack) {
  for (const BackendSettingsInfo& b : all_backends()) {
    BackendSettings defaults;
    std::string required;
    for (const SettingInfo& i : b.settings) {
      defaults[i.key] = i.value;
      if (kRequired.count(id(b) + "/" + i.key)) required = i.key;
    }
    Backend backend = make(b.stage, b.backend);
    const Status s = backend.configure(defaults);
    if (required.empty()) {
      EXPECT_TRUE(s.ok()) << id(b) << ": " << s.message();
      EXPECT_EQ(backend.info().size(), b.settings.size());
    } else {
      EXPECT_FALSE(s.ok()) << id(b) << " runs without " << required;
      EXPECT_NE(s.message().find(required + "="), std::string::npos) << s.message();
    }
  }
}

// A value just outside a number's described range, or "" when it has none.
std::string outside(const SettingInfo& i) {
  if (i.type == "integer") return "-1";  // every integer setting starts at 0 or above
  if (i.type != "number" || i.range.empty()) return "";
  if (i.range[0] == '(' || i.range[0] == '[' || i.range.rfind(">", 0) == 0) return "-1e300";
  return "";
}

TEST(BackendSettings, AValueOutsideTheRangeIsRefusedAndChangesNothing) {
  std::size_t tried = 0;
  for (const BackendSettingsInfo& b : all_backends()) {
    // Another valid value for a switch or choice, set in the same call: it
    // must not stay when the bad number is refused.
    std::string flip_key, flip_value;
    for (const SettingInfo& i : b.settings) {
      if (i.type == "on|off") {
        flip_key = i.key;
        flip_value = i.value == "on" ? "off" : "on";
      }
    }
    for (const SettingInfo& i : b.settings) {
      const std::string bad = outside(i);
      if (bad.empty()) continue;
      Backend backend = make(b.stage, b.backend);
      const std::vector<SettingInfo> before = backend.info();
      BackendSettings settings{{i.key, bad}};
      if (!flip_key.empty()) settings[flip_key] = flip_value;
      const Status s = backend.configure(settings);
      ASSERT_FALSE(s.ok()) << id(b) << ": " << i.key << "=" << bad << " accepted";
      EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
      EXPECT_NE(s.message().find("bad setting " + i.key + "=" + bad), std::string::npos) << s.message();
      const std::vector<SettingInfo> after = backend.info();
      ASSERT_EQ(after.size(), before.size());
      for (std::size_t k = 0; k < after.size(); ++k)
        EXPECT_EQ(after[k].value, before[k].value) << id(b) << ": " << after[k].key << " changed by a refused call";
      ++tried;
    }
  }
  EXPECT_GT(tried, 30u);
}

TEST(BackendSettings, UnknownKeysAreRefusedListingTheKnownOnes) {
  Result<std::unique_ptr<Refiner>> r = make_refiner("smooth", {{"lamda", "1"}});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(), "smooth: unknown setting 'lamda' (known: lambda, island, sweeps)");
  Result<std::unique_ptr<Refiner>> none = make_refiner("none", {{"x", "1"}});
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.status().message().find("takes no settings (got 'x')"), std::string::npos);
  Result<std::unique_ptr<Segmenter>> nosuch = make_segmenter("hybird");
  ASSERT_FALSE(nosuch.ok());
  EXPECT_NE(nosuch.status().message().find("no segmenter named 'hybird' (known: "), std::string::npos)
      << nosuch.status().message();
}

TEST(BackendSettings, DescribedByNameOrByStageAndName) {
  Result<std::vector<BackendSettingsInfo>> vlm = describe_backend_settings("vlm");
  ASSERT_TRUE(vlm.ok()) << vlm.status().message();
  std::set<std::string> stages;
  for (const BackendSettingsInfo& b : *vlm) stages.insert(to_string(b.stage));
  EXPECT_EQ(stages, (std::set<std::string>{"identify", "refine", "properties"}));
  Result<std::vector<BackendSettingsInfo>> one = describe_backend_settings("refine:vlm");
  ASSERT_TRUE(one.ok());
  ASSERT_EQ(one->size(), 1u);
  EXPECT_EQ(one->front().stage, Stage::kRefine);
  Result<std::vector<BackendSettingsInfo>> hybrid = describe_backend_settings("hybrid");
  ASSERT_TRUE(hybrid.ok());
  const std::vector<SettingInfo>& s = hybrid->front().settings;
  auto share = std::find_if(s.begin(), s.end(), [](const SettingInfo& i) { return i.key == "share"; });
  ASSERT_NE(share, s.end());
  EXPECT_EQ(share->value, "0.99");
  EXPECT_EQ(share->range, "(0, 1]");

  Result<std::vector<BackendSettingsInfo>> missing = describe_backend_settings("nosuch");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find("segment:hybrid"), std::string::npos) << missing.status().message();
  Result<std::vector<BackendSettingsInfo>> stage = describe_backend_settings("paint:vlm");
  ASSERT_FALSE(stage.ok());
  EXPECT_NE(stage.status().message().find("no stage named 'paint'"), std::string::npos);
}

// A configured backend describes its current values; a pipeline prepared
// with a bad setting fails before any work, naming it.
TEST(BackendSettings, ConfiguredValuesAreDescribedAndPipelinesCheckThemFirst) {
  Result<std::unique_ptr<Decomposer>> d = make_decomposer("voxel-cut", {{"resolution", "96"}});
  ASSERT_TRUE(d.ok());
  const std::vector<SettingInfo> info = (*d)->settings().info();
  ASSERT_FALSE(info.empty());
  EXPECT_EQ(info.front().key, "resolution");
  EXPECT_EQ(info.front().value, "96");

  PipelineOptions o;
  o.segmenter.settings = {{"share", "2"}};
  Pipeline p(o);
  const Status s = p.prepare();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("hybrid: bad setting share=2: share takes a number in (0, 1]"), std::string::npos)
      << s.message();
}

}  // namespace
}  // namespace g2p
