// Typed backend settings. A backend describes each of its KEY=VALUE settings
// once, bound to the member it sets: the key, its type, unit, range, default
// and a line of help. That one description
//   - validates and applies configure(): every setting is checked before any
//     is assigned, and a failed check afterwards restores them, so a bad
//     setting leaves the backend as it was;
//   - lists the settings (`g2p run --settings BACKEND`, Python's
//     g2p.backend_settings(), the stage pages in docs/).
//
//   SettingsSpec settings() override {
//     return SettingsSpec("voxel-cut")
//         .integer("resolution", resolution_, 8, 256, "cells", "voxels along the longest side")
//         .number("error", error_, Range::closed(0, 1), "", "largest hull volume error, of the part's volume");
//   }
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// Backend settings as given, key = value (`--set KEY=VALUE`).
using BackendSettings = std::map<std::string, std::string>;

// One setting as a user sees it.
struct G2P_API SettingInfo {
  std::string key;
  std::string type;   // "number", "integer", "on|off", "choice", "text" or "file"
  std::string unit;   // "s", "m", "degrees", "cells", ...; "" for a ratio, count or word
  std::string range;  // the values it takes: "(0, 1]", "8..256", "model|material"; "" for any text
  std::string value;  // a new backend's default (a configured one's current value), as written in --set
  std::string help;   // one line

  // What it takes, in words: "a number in (0, 1]", "an integer in 0..256
  // (cells)", "on or off", "one of model|material", "an existing file".
  std::string takes() const;
};

// The interval a number may take.
struct G2P_API Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false, max_open = false;  // the end itself excluded

  static Range closed(double lo, double hi) { return {lo, hi, false, false}; }      // [lo, hi]
  static Range at_least(double lo) { return {lo, Range{}.max, false, true}; }       // [lo, inf)
  static Range above(double lo) { return {lo, Range{}.max, true, true}; }           // (lo, inf)
  static Range above_to(double lo, double hi) { return {lo, hi, true, false}; }     // (lo, hi]
  static Range up_to_below(double lo, double hi) { return {lo, hi, false, true}; }  // [lo, hi)
  bool contains(double v) const;
  std::string text() const;  // "(0, 1]", ">= 0", "> 0"
};

// A backend's settings bound to its members. Built by the backend on demand
// (it holds references into the backend: use it while the backend lives).
class G2P_API SettingsSpec {
 public:
  explicit SettingsSpec(std::string backend);

  // A real number in `range`.
  SettingsSpec& number(const char* key, double& member, Range range, const char* unit, const char* help);
  SettingsSpec& number(const char* key, float& member, Range range, const char* unit, const char* help);
  // A whole number in [min, max].
  SettingsSpec& integer(const char* key, int& member, int min, int max, const char* unit, const char* help);
  SettingsSpec& integer(const char* key, std::size_t& member, std::size_t min, std::size_t max, const char* unit,
                        const char* help);
  // on or off.
  SettingsSpec& flag(const char* key, bool& member, const char* help);
  // Any text (a model name, a URL, a command line).
  SettingsSpec& text(const char* key, std::string& member, const char* help);
  // A path to an existing file; "" leaves the backend's own choice.
  SettingsSpec& file(const char* key, std::string& member, const char* help);
  // One of the words, each standing for a value of `member`.
  template <typename T>
  SettingsSpec& choice(const char* key, T& member, std::vector<std::pair<std::string, T>> words, const char* help);
  // The last number also takes the word `word`, which sets it to `value`
  // (names=off in the segmenters).
  SettingsSpec& or_word(const char* word, double value);
  // Runs after every given setting is assigned; an error restores them all
  // (settings that only make sense together, a client built from them).
  SettingsSpec& check(std::function<Status()> after);
  // Another backend's settings, applied with these (a backend that wraps one).
  SettingsSpec& include(SettingsSpec other);

  // Checks every setting, then assigns them; all or none. Errors name the
  // backend, the key and the values it takes.
  Status apply(const BackendSettings& settings) const;
  // The settings, in the order they were described, with their current values.
  std::vector<SettingInfo> info() const;
  const std::string& backend() const { return backend_; }

 private:
  // One bound setting: how to describe it, check a value, and assign it.
  struct Binding {
    SettingInfo info;
    std::function<std::string()> current;  // the member, as written
    // Checks `value`; on success returns the assignment to run later.
    std::function<bool(const std::string& value, std::function<void()>& assign)> parse;
    std::function<std::function<void()>()> save;  // returns the restoring assignment
    double* number = nullptr;                     // the member of number(double&), for or_word
  };

  SettingsSpec& add(Binding b);

  std::string backend_;
  std::vector<Binding> bindings_;
  std::vector<std::function<Status()>> checks_;
};

// ---- Implementation of the template ---------------------------------------

template <typename T>
SettingsSpec& SettingsSpec::choice(const char* key, T& member, std::vector<std::pair<std::string, T>> words,
                                   const char* help) {
  Binding b;
  b.info.key = key;
  b.info.type = "choice";
  for (const auto& w : words) b.info.range += (b.info.range.empty() ? "" : "|") + w.first;
  b.info.help = help;
  auto shared = std::make_shared<std::vector<std::pair<std::string, T>>>(std::move(words));
  T* m = &member;
  b.current = [m, shared] {
    for (const auto& w : *shared)
      if (w.second == *m) return w.first;
    return std::string();
  };
  b.parse = [m, shared](const std::string& value, std::function<void()>& assign) {
    for (const auto& w : *shared)
      if (w.first == value) {
        const T v = w.second;
        assign = [m, v] { *m = v; };
        return true;
      }
    return false;
  };
  b.save = [m] {
    const T old = *m;
    return std::function<void()>([m, old] { *m = old; });
  };
  return add(std::move(b));
}

}  // namespace g2p
