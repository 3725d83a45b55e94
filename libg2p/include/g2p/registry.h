// Registry<Interface>: stage backends by name, for CLI flags such as
// `--segmenter NAME` and for researchers who plug in their own. Each stage
// header exposes one registry; libg2p registers its built-in backends
// explicitly when the registry is first used (no static self-registration,
// which linkers drop).
#pragma once

#include <algorithm>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "g2p/settings.h"
#include "g2p/status.h"

namespace g2p {

template <typename Interface>
class Registry {
 public:
  using Factory = std::function<std::unique_ptr<Interface>()>;

  // `kind` names the stage's backends in messages ("segmenter").
  explicit Registry(std::string kind = "backend") : kind_(std::move(kind)) {}

  // Adds a backend. Fails if the name is empty or taken.
  Status add(const std::string& name, Factory factory) {
    if (name.empty() || !factory) return Status::InvalidArgument("a backend needs a name and a factory");
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& entry : entries_)
      if (entry.first == name) return Status::InvalidArgument("a backend named '" + name + "' is already registered");
    entries_.emplace_back(name, std::move(factory));
    return Status::Ok();
  }

  // A new instance of the backend called `name`; the error lists the names.
  Result<std::unique_ptr<Interface>> create(const std::string& name) const {
    Factory factory;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const auto& entry : entries_)
        if (entry.first == name) factory = entry.second;
    }
    if (!factory) {
      std::string known;
      for (const std::string& n : names()) known += (known.empty() ? "" : ", ") + n;
      return Status::NotFound("no " + kind_ + " named '" + name + "' (known: " + known + ")");
    }
    std::unique_ptr<Interface> instance = factory();
    if (!instance) return Status::Internal("the factory of backend '" + name + "' returned nothing");
    return instance;
  }

  // A new instance of `name` with `settings` applied (its configure(): all or
  // none, errors naming the setting): how every stage makes its backends.
  Result<std::unique_ptr<Interface>> make(const std::string& name, const BackendSettings& settings = {}) const {
    Result<std::unique_ptr<Interface>> made = create(name);
    if (!made.ok()) return made.status();
    G2P_RETURN_IF_ERROR((*made)->configure(settings));
    return made;
  }

  // The settings backend `name` takes, with a new instance's defaults.
  Result<std::vector<SettingInfo>> settings(const std::string& name) const {
    Result<std::unique_ptr<Interface>> made = create(name);
    if (!made.ok()) return made.status();
    return (*made)->settings().info();
  }

  const std::string& kind() const { return kind_; }

  std::vector<std::string> names() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> out;
    for (const auto& entry : entries_) out.push_back(entry.first);
    return out;
  }

  bool contains(const std::string& name) const {
    const std::vector<std::string> all = names();
    return std::find(all.begin(), all.end(), name) != all.end();
  }

 private:
  std::string kind_;
  mutable std::mutex mutex_;
  std::vector<std::pair<std::string, Factory>> entries_;  // in registration order
};

}  // namespace g2p
