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

#include "g2p/status.h"

namespace g2p {

// Backend settings, key = value (keys are documented per backend in docs/,
// one page per stage).
using BackendSettings = std::map<std::string, std::string>;

template <typename Interface>
class Registry {
 public:
  using Factory = std::function<std::unique_ptr<Interface>()>;

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
      return Status::NotFound("no backend named '" + name + "' (known: " + known + ")");
    }
    std::unique_ptr<Interface> instance = factory();
    if (!instance) return Status::Internal("the factory of backend '" + name + "' returned nothing");
    return instance;
  }

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
  mutable std::mutex mutex_;
  std::vector<std::pair<std::string, Factory>> entries_;  // in registration order
};

}  // namespace g2p
