// SettingsSpec: typed settings bound to members, applied all or none.
#include "g2p/settings.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

namespace g2p {
namespace {

// A backend's worth of members of every kind.
struct Knobs {
  double share = 0.5;
  double names = 0.9;
  float temperature = 1.f;
  int sweeps = 50;
  std::size_t bytes = 4096;
  bool colour = true;
  enum class Unnamed { kPbr, kNetwork } unnamed = Unnamed::kPbr;
  std::string model, card;
  int checks = 0;

  SettingsSpec spec() {
    return SettingsSpec("knobs")
        .number("share", share, Range::above_to(0, 1), "", "a share")
        .number("names", names, Range::above_to(0, 1), "", "a threshold")
        .or_word("off", 2.0)
        .number("temperature", temperature, Range::above(0), "", "softness")
        .integer("sweeps", sweeps, 0, 1000, "", "sweeps")
        .integer("bytes", bytes, std::size_t{1}, std::size_t{1000000}, "bytes", "a size")
        .flag("colour", colour, "colour counts")
        .choice("unnamed", unnamed, {{"pbr", Unnamed::kPbr}, {"network", Unnamed::kNetwork}}, "rule 4")
        .text("model", model, "a model name")
        .file("card", card, "a card");
  }
};

TEST(SettingsSpec, AppliesEveryKindOfSetting) {
  Knobs k;
  ASSERT_TRUE(k.spec()
                  .apply({{"share", "0.25"},
                          {"names", "off"},
                          {"temperature", "2.5"},
                          {"sweeps", "7"},
                          {"bytes", "100"},
                          {"colour", "off"},
                          {"unnamed", "network"},
                          {"model", "qwen"}})
                  .ok());
  EXPECT_DOUBLE_EQ(k.share, 0.25);
  EXPECT_DOUBLE_EQ(k.names, 2.0);
  EXPECT_FLOAT_EQ(k.temperature, 2.5f);
  EXPECT_EQ(k.sweeps, 7);
  EXPECT_EQ(k.bytes, 100u);
  EXPECT_FALSE(k.colour);
  EXPECT_EQ(k.unnamed, Knobs::Unnamed::kNetwork);
  EXPECT_EQ(k.model, "qwen");
}

TEST(SettingsSpec, DescribesEachSettingWithItsCurrentValue) {
  Knobs k;
  std::vector<SettingInfo> info = k.spec().info();
  ASSERT_EQ(info.size(), 9u);
  EXPECT_EQ(info[0].key, "share");
  EXPECT_EQ(info[0].type, "number");
  EXPECT_EQ(info[0].range, "(0, 1]");
  EXPECT_EQ(info[0].value, "0.5");
  EXPECT_EQ(info[1].range, "(0, 1] or off");
  EXPECT_EQ(info[2].range, "> 0");
  EXPECT_EQ(info[3].range, "0..1000");
  EXPECT_EQ(info[4].unit, "bytes");
  EXPECT_EQ(info[5].type, "on|off");
  EXPECT_EQ(info[5].value, "on");
  EXPECT_EQ(info[6].range, "pbr|network");
  EXPECT_EQ(info[6].value, "pbr");
  EXPECT_EQ(info[8].type, "file");
  k.names = 2.0;
  k.sweeps = 3;
  info = k.spec().info();
  EXPECT_EQ(info[1].value, "off");
  EXPECT_EQ(info[3].value, "3");
  // Every described value is accepted back as written.
  BackendSettings again;
  for (const SettingInfo& i : info) again[i.key] = i.value;
  Knobs copy = k;
  EXPECT_TRUE(copy.spec().apply(again).ok());
  EXPECT_EQ(copy.spec().info()[1].value, "off");
}

TEST(SettingsSpec, RejectsBadValuesNamingTheSettingAndWhatItTakes) {
  struct Case {
    const char* key;
    const char* value;
    const char* says;
  };
  const Case cases[] = {{"share", "0", "share takes a number in (0, 1]"},
                        {"share", "1.5", "(0, 1]"},
                        {"share", "nan", "(0, 1]"},
                        {"share", "0.5x", "(0, 1]"},
                        {"names", "of", "(0, 1] or off"},
                        {"temperature", "0", "> 0"},
                        {"sweeps", "2.5", "an integer in 0..1000"},
                        {"sweeps", "-1", "0..1000"},
                        {"bytes", "0", "1..1000000 (bytes)"},
                        {"colour", "yes", "on or off"},
                        {"unnamed", "nameless", "one of pbr|network"},
                        {"card", "/no/such/card.json", "an existing file"}};
  for (const Case& c : cases) {
    Knobs k;
    const Status s = k.spec().apply({{c.key, c.value}});
    ASSERT_FALSE(s.ok()) << c.key << "=" << c.value;
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
    EXPECT_NE(s.message().find(std::string("knobs: bad setting ") + c.key + "=" + c.value), std::string::npos)
        << s.message();
    EXPECT_NE(s.message().find(c.says), std::string::npos) << s.message();
  }
}

TEST(SettingsSpec, UnknownKeysListTheKnownOnes) {
  Knobs k;
  const Status s = k.spec().apply({{"shares", "0.5"}});
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("knobs: unknown setting 'shares' (known: share, names, temperature"), std::string::npos)
      << s.message();
  const Status empty = SettingsSpec("plain").apply({{"x", "1"}});
  EXPECT_NE(empty.message().find("plain: takes no settings (got 'x')"), std::string::npos) << empty.message();
  EXPECT_TRUE(SettingsSpec("plain").apply({}).ok());
}

TEST(SettingsSpec, ABadSettingLeavesEveryMemberAsItWas) {
  Knobs k;
  // std::map orders the keys: colour, share and sweeps are good and come
  // before the bad `unnamed`.
  const Status s = k.spec().apply({{"colour", "off"}, {"share", "0.1"}, {"sweeps", "9"}, {"unnamed", "bad"}});
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(k.colour);
  EXPECT_DOUBLE_EQ(k.share, 0.5);
  EXPECT_EQ(k.sweeps, 50);
  // ... and an unknown key after good ones too.
  ASSERT_FALSE(k.spec().apply({{"colour", "off"}, {"zzz", "1"}}).ok());
  EXPECT_TRUE(k.colour);
}

TEST(SettingsSpec, AFailedCheckRestoresTheValuesItSaw) {
  Knobs k;
  double seen = 0;
  auto spec = [&] {
    return k.spec().check([&]() -> Status {
      seen = k.share;
      ++k.checks;
      if (k.model.empty()) return Status::InvalidArgument("knobs: needs the setting model=NAME");
      return Status::Ok();
    });
  };
  const Status s = spec().apply({{"share", "0.2"}});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(), "knobs: needs the setting model=NAME");
  EXPECT_DOUBLE_EQ(seen, 0.2);     // the check saw the new value...
  EXPECT_DOUBLE_EQ(k.share, 0.5);  // ...which did not stay
  EXPECT_TRUE(spec().apply({{"share", "0.2"}, {"model", "m"}}).ok());
  EXPECT_DOUBLE_EQ(k.share, 0.2);
  EXPECT_EQ(k.checks, 2);
}

TEST(SettingsSpec, IncludesAWrappedBackendsSettings) {
  Knobs outer, inner;
  SettingsSpec spec = SettingsSpec("outer")
                          .flag("colour", outer.colour, "outer's")
                          .include(SettingsSpec("inner").integer("sweeps", inner.sweeps, 0, 10, "", "inner's"));
  ASSERT_TRUE(spec.apply({{"colour", "off"}, {"sweeps", "3"}}).ok());
  EXPECT_FALSE(outer.colour);
  EXPECT_EQ(inner.sweeps, 3);
  EXPECT_EQ(spec.info().size(), 2u);
}

TEST(SettingsSpec, FilesMustExist) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "g2p_settings_test_card.json";
  std::ofstream(path) << "{}";
  Knobs k;
  EXPECT_TRUE(k.spec().apply({{"card", path.string()}}).ok());
  EXPECT_EQ(k.card, path.string());
  EXPECT_TRUE(k.spec().apply({{"card", ""}}).ok());  // "" = the backend's own choice
  std::filesystem::remove(path);
}

TEST(Range, TextAndMembership) {
  EXPECT_EQ(Range::closed(8, 256).text(), "[8, 256]");
  EXPECT_EQ(Range::at_least(0).text(), ">= 0");
  EXPECT_EQ(Range::up_to_below(0, 0.5).text(), "[0, 0.5)");
  EXPECT_EQ(Range::closed(1e3, 1e9).text(), "[1000, 1e+09]");
  EXPECT_TRUE(Range::above_to(0, 1).contains(1));
  EXPECT_FALSE(Range::above_to(0, 1).contains(0));
  EXPECT_FALSE(Range::up_to_below(0, 0.5).contains(0.5));
  EXPECT_FALSE(Range::at_least(0).contains(-1e-300));
}

}  // namespace
}  // namespace g2p
