// The shipped WordNet synsets by kind (backends.h): libg2p/data/wordnet_kinds.json,
// built by scripts/objects/build_objects.py with the object table and
// embedded like it. Parsed on the first lookup only, so that runs that never
// ask pay nothing at start.
#include <map>

#include <nlohmann/json.hpp>

#include "identify/backends.h"

namespace g2p {

extern const char* const kWordnetKindsJson[];  // generated from data/wordnet_kinds.json

const std::string& detail::shipped_wordnet_kind(long offset) {
  static const std::map<long, std::string>* by_offset = [] {
    auto* m = new std::map<long, std::string>();  // never destroyed: usable during static destruction
    std::string text;
    for (const char* const* chunk = kWordnetKindsJson; *chunk != nullptr; ++chunk) text += *chunk;
    const nlohmann::json doc = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
    // Checked by the tests (ClassifierIdentifier.*); a broken file maps nothing.
    if (doc.is_object() && doc.value("format", std::string()) == "g2p-wordnet-kinds" && doc.contains("kinds") &&
        doc["kinds"].is_object())
      for (const auto& [kind, offsets] : doc["kinds"].items())
        if (offsets.is_array())
          for (const nlohmann::json& o : offsets)
            if (o.is_number_integer()) m->emplace(o.get<long>(), kind);
    return m;
  }();
  static const std::string none;
  const auto it = by_offset->find(offset);
  return it == by_offset->end() ? none : it->second;
}

}  // namespace g2p
