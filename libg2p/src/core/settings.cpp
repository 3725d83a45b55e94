// SettingsSpec: typed backend settings, checked all before any is assigned.
#include "g2p/settings.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace g2p {
namespace {

// The whole of `s` as a finite number; false for "", "1x", "nan", "inf".
bool parse_number(const std::string& s, double& out) {
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return end != s.c_str() && *end == '\0' && std::isfinite(out);
}

// Shortest text that reads back as `v` (0.5, 1e-06, 2048).
std::string number_text(double v) {
  char buffer[32];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
    if (std::strtod(buffer, nullptr) == v) break;
  }
  return buffer;
}

template <typename T>
std::function<std::function<void()>()> saver(T* m) {
  return [m] {
    const T old = *m;
    return std::function<void()>([m, old] { *m = old; });
  };
}

}  // namespace

std::string SettingInfo::takes() const {
  std::string out;
  if (type == "number")
    out = "a number";
  else if (type == "integer")
    out = "an integer";
  else if (type == "on|off")
    out = "on or off";
  else if (type == "choice")
    out = "one of";
  else if (type == "file")
    out = "an existing file";
  else
    out = "any text";
  if (!range.empty()) {
    const char c = range[0];
    out += (c == '(' || c == '[' || (c >= '0' && c <= '9')) ? " in " + range : " " + range;
  }
  if (!unit.empty()) out += " (" + unit + ")";
  return out;
}

bool Range::contains(double v) const {
  if (min_open ? !(v > min) : !(v >= min)) return false;
  return max_open ? v < max : v <= max;
}

std::string Range::text() const {
  const bool no_min = std::isinf(min), no_max = std::isinf(max);
  if (no_min && no_max) return "any number";
  if (no_max) return (min_open ? "> " : ">= ") + number_text(min);
  if (no_min) return (max_open ? "< " : "<= ") + number_text(max);
  return std::string(min_open ? "(" : "[") + number_text(min) + ", " + number_text(max) + (max_open ? ")" : "]");
}

SettingsSpec::SettingsSpec(std::string backend) : backend_(std::move(backend)) {}

SettingsSpec& SettingsSpec::add(Binding b) {
  bindings_.push_back(std::move(b));
  return *this;
}

SettingsSpec& SettingsSpec::number(const char* key, double& member, Range range, const char* unit, const char* help) {
  double* m = &member;
  Binding b;
  b.info = {key, "number", unit, range.text(), "", help};
  b.current = [m] { return number_text(*m); };
  b.parse = [m, range](const std::string& value, std::function<void()>& assign) {
    double v = 0;
    if (!parse_number(value, v) || !range.contains(v)) return false;
    assign = [m, v] { *m = v; };
    return true;
  };
  b.save = saver(m);
  b.number = m;
  return add(std::move(b));
}

SettingsSpec& SettingsSpec::number(const char* key, float& member, Range range, const char* unit, const char* help) {
  float* m = &member;
  Binding b;
  b.info = {key, "number", unit, range.text(), "", help};
  b.current = [m] { return number_text(*m); };
  b.parse = [m, range](const std::string& value, std::function<void()>& assign) {
    double v = 0;
    if (!parse_number(value, v) || !range.contains(v) || !std::isfinite(static_cast<float>(v))) return false;
    assign = [m, v] { *m = static_cast<float>(v); };
    return true;
  };
  b.save = saver(m);
  return add(std::move(b));
}

SettingsSpec& SettingsSpec::integer(const char* key, int& member, int min, int max, const char* unit,
                                    const char* help) {
  int* m = &member;
  Binding b;
  b.info = {key, "integer", unit, std::to_string(min) + ".." + std::to_string(max), "", help};
  b.current = [m] { return std::to_string(*m); };
  b.parse = [m, min, max](const std::string& value, std::function<void()>& assign) {
    double v = 0;
    if (!parse_number(value, v) || v != std::floor(v) || v < min || v > max) return false;
    assign = [m, v] { *m = static_cast<int>(v); };
    return true;
  };
  b.save = saver(m);
  return add(std::move(b));
}

SettingsSpec& SettingsSpec::integer(const char* key, std::size_t& member, std::size_t min, std::size_t max,
                                    const char* unit, const char* help) {
  std::size_t* m = &member;
  Binding b;
  b.info = {key, "integer", unit, std::to_string(min) + ".." + std::to_string(max), "", help};
  b.current = [m] { return std::to_string(*m); };
  b.parse = [m, min, max](const std::string& value, std::function<void()>& assign) {
    double v = 0;
    if (!parse_number(value, v) || v != std::floor(v) || v < static_cast<double>(min) || v > static_cast<double>(max))
      return false;
    assign = [m, v] { *m = static_cast<std::size_t>(v); };
    return true;
  };
  b.save = saver(m);
  return add(std::move(b));
}

SettingsSpec& SettingsSpec::flag(const char* key, bool& member, const char* help) {
  choice(key, member, {{"on", true}, {"off", false}}, help);
  bindings_.back().info.type = "on|off";
  bindings_.back().info.range.clear();
  return *this;
}

SettingsSpec& SettingsSpec::text(const char* key, std::string& member, const char* help) {
  std::string* m = &member;
  Binding b;
  b.info = {key, "text", "", "", "", help};
  b.current = [m] { return *m; };
  b.parse = [m](const std::string& value, std::function<void()>& assign) {
    assign = [m, value] { *m = value; };
    return true;
  };
  b.save = saver(m);
  return add(std::move(b));
}

SettingsSpec& SettingsSpec::file(const char* key, std::string& member, const char* help) {
  text(key, member, help);
  Binding& b = bindings_.back();
  b.info.type = "file";
  std::string* m = &member;
  b.parse = [m](const std::string& value, std::function<void()>& assign) {
    std::error_code ec;
    if (!value.empty() && !std::filesystem::is_regular_file(value, ec)) return false;
    assign = [m, value] { *m = value; };
    return true;
  };
  return *this;
}

SettingsSpec& SettingsSpec::or_word(const char* word, double value) {
  if (bindings_.empty() || bindings_.back().number == nullptr) return *this;  // only after number(double&)
  Binding& b = bindings_.back();
  b.info.range += std::string(" or ") + word;
  double* m = b.number;
  const std::string w = word;
  b.current = [current = b.current, m, w, value] { return *m == value ? w : current(); };
  b.parse = [parse = b.parse, m, w, value](const std::string& text, std::function<void()>& assign) {
    if (text != w) return parse(text, assign);
    assign = [m, value] { *m = value; };
    return true;
  };
  return *this;
}

SettingsSpec& SettingsSpec::check(std::function<Status()> after) {
  if (after) checks_.push_back(std::move(after));
  return *this;
}

SettingsSpec& SettingsSpec::include(SettingsSpec other) {
  for (Binding& b : other.bindings_) bindings_.push_back(std::move(b));
  for (auto& c : other.checks_) checks_.push_back(std::move(c));
  return *this;
}

Status SettingsSpec::apply(const BackendSettings& settings) const {
  std::vector<std::function<void()>> assignments, restores;
  for (const auto& [key, value] : settings) {
    const Binding* found = nullptr;
    for (const Binding& b : bindings_)
      if (b.info.key == key) found = &b;
    if (found == nullptr) {
      if (bindings_.empty()) return Status::InvalidArgument(backend_ + ": takes no settings (got '" + key + "')");
      std::string known;
      for (const Binding& b : bindings_) known += (known.empty() ? "" : ", ") + b.info.key;
      return Status::InvalidArgument(backend_ + ": unknown setting '" + key + "' (known: " + known + ")");
    }
    std::function<void()> assign;
    if (!found->parse(value, assign) || !assign) {
      return Status::InvalidArgument(backend_ + ": bad setting " + key + "=" + value + ": " + key + " takes " +
                                     found->info.takes());
    }
    assignments.push_back(std::move(assign));
    restores.push_back(found->save());
  }
  for (const auto& a : assignments) a();
  for (const auto& c : checks_) {
    const Status s = c();
    if (s.ok()) continue;
    for (auto r = restores.rbegin(); r != restores.rend(); ++r) (*r)();
    return s;
  }
  return Status::Ok();
}

std::vector<SettingInfo> SettingsSpec::info() const {
  std::vector<SettingInfo> out;
  for (const Binding& b : bindings_) {
    out.push_back(b.info);
    out.back().value = b.current();
  }
  return out;
}

}  // namespace g2p
