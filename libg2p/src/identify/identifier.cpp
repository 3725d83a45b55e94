// The Identifier base class, the registry, and the backends that read words:
// "object" (the user's), "names" (the file's), "auto" (both, with the
// detector) and "none".
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <future>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "core/json_text.h"
#include "g2p/identify.h"
#include "g2p/segment.h"
#include "identify/backends.h"

namespace g2p {

Identifier::~Identifier() = default;

SettingsSpec Identifier::settings() { return SettingsSpec("this identifier"); }

Status Identifier::configure(const BackendSettings& settings) { return this->settings().apply(settings); }

namespace {

const ObjectTable& table_of(const IdentifyInput& in) {
  return in.table != nullptr ? *in.table : ObjectTable::shipped();
}

std::string percent(double x) {
  char b[16];
  std::snprintf(b, sizeof b, "%.0f %%", 100.0 * x);
  return b;
}

// Always unknown: the runs before identification existed.
class NoIdentifier final : public Identifier {
 public:
  Result<Identification> identify(const IdentifyInput&) const override {
    Identification id;
    id.notes.push_back("none: not identified");
    return id;
  }
};

// The user's words (g2p run --object): the kind they name, or an error
// naming the nearest kinds.
class ObjectIdentifier final : public Identifier {
 public:
  Result<Identification> identify(const IdentifyInput& in) const override {
    Identification id;
    if (in.object_text.empty()) {
      id.notes.push_back("object: no words given (--object)");
      return id;
    }
    const ObjectTable& table = table_of(in);
    const std::vector<TextMatch> matches = table.match(in.object_text);
    if (matches.empty()) {
      Result<std::string> kind = kind_from_text(table, in.object_text);
      return kind.status();
    }
    for (std::size_t i = 0; i < matches.size(); ++i) {
      const ObjectKind& k = table.kinds()[static_cast<std::size_t>(matches[i].kind)];
      // The words are the user's: the first kind they name is certain, others are what they also mentioned.
      id.candidates.push_back(
          {k.name, i == 0 ? 1.0 : 0.2, "object", "the words '" + in.object_text + "' (\"" + matches[i].term + "\")"});
    }
    return id;
  }
};

// The names a file carries: its own name (unless names were removed), its
// nodes and meshes (material names are left out: they name materials and
// colours, "oak", "black velvet", not the object) and placeholders
// (is_placeholder_name: Blender's "Plane.003" is no airplane, "Cube" no
// puzzle cube) are left out. Each name votes for the
// kind it names best: the file name 1, each node or mesh name 0.5 (at most
// 1 a kind, so the file's own name wins a tie with its parts' names); a kind's confidence is its votes over all votes
// plus 0.5, at most 0.9 (names are often stale).
class NamesIdentifier final : public Identifier {
 public:
  Result<Identification> identify(const IdentifyInput& in) const override {
    Identification id;
    if (in.model == nullptr) return Status::InvalidArgument("identify (names): no model");
    const ObjectTable& table = table_of(in);
    struct Vote {
      double file = 0, nodes = 0;
      std::vector<std::string> why;
      double total() const { return file + std::min(nodes, 1.0); }
    };
    std::map<int, Vote> votes;
    auto vote = [&](const std::string& name, double weight, double Vote::*slot, const char* what) {
      const std::vector<TextMatch> m = table.match(name);
      if (m.empty()) return;
      Vote& v = votes[m.front().kind];
      v.*slot += weight;
      if (v.why.size() < 3) v.why.push_back(std::string(what) + " '" + name + "'");
    };
    const std::string stem = std::filesystem::path(in.model->info.path).stem().string();
    if (in.use_file_name && !stem.empty() && !is_placeholder_name(stem)) vote(stem, 1.0, &Vote::file, "file name");
    std::set<std::string> names;
    for (const SourcePrimitive& p : in.model->primitives) {
      if (!p.node_name.empty()) names.insert(p.node_name);
      if (!p.mesh_name.empty()) names.insert(p.mesh_name);
    }
    for (const std::string& n : names)  // Blender's "Plane.003" names no airplane
      if (!is_placeholder_name(n)) vote(n, 0.5, &Vote::nodes, "node or mesh name");
    double all = 0;
    for (const auto& [kind, v] : votes) all += v.total();
    // Most votes first; on a tie the kind the file's own name gives (its
    // "sofa2" over the "Cushion" parts it is made of).
    std::vector<std::pair<int, const Vote*>> ranked;
    for (const auto& [kind, v] : votes) ranked.emplace_back(kind, &v);
    std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) {
      return a.second->total() != b.second->total() ? a.second->total() > b.second->total()
                                                    : a.second->file > b.second->file;
    });
    for (const auto& [kind, v] : ranked) {
      std::string why;
      for (const std::string& w : v->why) why += (why.empty() ? "" : ", ") + w;
      id.candidates.push_back(
          {table.kinds()[static_cast<std::size_t>(kind)].name, std::min(0.9, v->total() / (all + 0.5)), "names", why});
    }
    if (id.candidates.empty()) id.notes.push_back("names: no name in the file names a kind of the object table");
    return id;
  }
};

// "auto": the user's words win when given (the names are compared with them
// and a disagreement is noted); else the names, the detector and the kind
// classifier (the shipped one, or the user's), each kind's confidences joined
// as independent evidence, 1 - (1 - a)(1 - b).
class AutoIdentifier final : public Identifier {
 public:
  AutoIdentifier()
      : names_(std::make_unique<NamesIdentifier>()),
        detector_(detail::make_detector_identifier()),
        classifier_(detail::make_classifier_identifier()) {}

  SettingsSpec settings() override {
    return SettingsSpec("auto")
        .flag("detector", use_detector_, "join the detector's answer with the names'")
        .flag("classifier", use_classifier_, "join the kind classifier's answer (the shipped one, or model=PATH)")
        .include(detector_->settings())
        .include(classifier_->settings());
  }

  Result<Identification> identify(const IdentifyInput& in) const override {
    Result<Identification> by_names = names_->identify(in);
    if (!by_names.ok()) return by_names.status();
    if (!in.object_text.empty()) {
      Result<Identification> words = ObjectIdentifier().identify(in);
      if (!words.ok()) return words.status();
      Identification id = std::move(*words);
      if (by_names->known() && by_names->kind() != id.kind())
        id.notes.push_back("the names say " + by_names->kind() + " (" + percent(by_names->confidence()) + ", " +
                           by_names->candidates.front().evidence + "); the user's words win");
      return id;
    }
    Identification id;
    std::map<std::string, KindGuess> joined;
    auto join = [&](const Identification& part) {
      for (const KindGuess& g : part.candidates) {
        auto [it, fresh] = joined.emplace(g.kind, g);
        if (fresh) continue;
        KindGuess& j = it->second;
        j.confidence = 1.0 - (1.0 - j.confidence) * (1.0 - g.confidence);
        j.source += "+" + g.source;
        j.evidence += "; " + g.evidence;
      }
      id.notes.insert(id.notes.end(), part.notes.begin(), part.notes.end());
      id.warnings.insert(id.warnings.end(), part.warnings.begin(), part.warnings.end());
    };
    join(*by_names);
    // A source that reads the views: its answer joined, a failure a warning.
    // The detector and the classifier load, render and infer side by side
    // (each loads its network on one core, and neither keeps both busy all
    // the time); their answers are joined in a fixed order, so the result is
    // the same as one after the other.
    const bool has_views = (in.views != nullptr && !in.views->empty()) || in.renderer != nullptr;
    const bool detect = use_detector_ && has_views, classify = use_classifier_ && has_views;
    auto run = [&in](const Identifier& source) -> Result<Identification> {
      try {
        return source.identify(in);
      } catch (const std::exception& e) {
        return Status::Internal(e.what());
      }
    };
    std::future<Result<Identification>> classified;
    if (detect && classify) classified = std::async(std::launch::async, run, std::cref(*classifier_));
    auto look = [&](Result<Identification> seen, const char* who) {
      if (!seen.ok()) {
        id.warnings.push_back(std::string("the ") + who + " failed (" + seen.status().message() +
                              "); identified without it");
        return;
      }
      if (seen->known() && by_names->known() && seen->kind() != by_names->kind())
        id.notes.push_back("the names say " + by_names->kind() + " (" + percent(by_names->confidence()) + "), the " +
                           who + " " + seen->kind() + " (" + percent(seen->confidence()) + ")");
      join(*seen);
    };
    if (detect) look(run(*detector_), "detector");
    if (classify) look(classified.valid() ? classified.get() : run(*classifier_), "classifier");
    for (auto& [kind, g] : joined) id.candidates.push_back(std::move(g));
    std::stable_sort(id.candidates.begin(), id.candidates.end(),
                     [](const KindGuess& a, const KindGuess& b) { return a.confidence > b.confidence; });
    return id;
  }

 private:
  std::unique_ptr<Identifier> names_;
  std::unique_ptr<Identifier> detector_;
  std::unique_ptr<Identifier> classifier_;
  bool use_detector_ = true;
  bool use_classifier_ = true;
};

}  // namespace

Registry<Identifier>& identifier_registry() {
  static Registry<Identifier>* registry = [] {
    auto* r = new Registry<Identifier>("identifier");  // never destroyed: usable during static destruction
    (void)r->add("auto", [] { return std::unique_ptr<Identifier>(std::make_unique<AutoIdentifier>()); });
    (void)r->add("object", [] { return std::unique_ptr<Identifier>(std::make_unique<ObjectIdentifier>()); });
    (void)r->add("names", [] { return std::unique_ptr<Identifier>(std::make_unique<NamesIdentifier>()); });
    (void)r->add("detector", &detail::make_detector_identifier);
    (void)r->add("classifier", &detail::make_classifier_identifier);
    (void)r->add("vlm", [] { return detail::make_vlm_identifier(); });
    (void)r->add("none", [] { return std::unique_ptr<Identifier>(std::make_unique<NoIdentifier>()); });
    return r;
  }();
  return *registry;
}

Result<Identification> identify(const IdentifyInput& input) { return AutoIdentifier().identify(input); }

Result<std::string> kind_from_text(const ObjectTable& table, const std::string& text, const std::string& flag) {
  const std::vector<TextMatch> m = table.match(text);
  if (!m.empty()) return table.kinds()[static_cast<std::size_t>(m.front().kind)].name;
  std::string near;
  for (const std::string& n : table.nearest(text, 5)) near += (near.empty() ? "" : ", ") + n;
  return Status::NotFound(flag + " '" + text + "' names no kind of the object table (" + std::to_string(table.size()) +
                          " kinds; `g2p identify --list` shows them); nearest: " + near);
}

const char* to_string(SizePolicy policy) { return policy == SizePolicy::kFile ? "file" : "kind"; }

Result<SizePolicy> parse_size_policy(const std::string& text) {
  if (text == "kind") return SizePolicy::kKind;
  if (text == "file") return SizePolicy::kFile;
  return Status::InvalidArgument("--size-from must be kind or file, got '" + text + "'");
}

std::string object_kinds_json(const ObjectTable& table) {
  nlohmann::json kinds = nlohmann::json::array();
  for (const ObjectKind& k : table.kinds())
    kinds.push_back({{"name", k.name},
                     {"group", k.group},
                     {"coco", k.coco},
                     {"typical_longest_side_m", k.typical_longest_side_m},
                     {"mass_kg", {k.mass_kg[0], k.mass_kg[1]}},
                     {"structure", k.structure}});
  return detail::json_text(kinds, 2);
}

std::string identification_json(const Identification& id, const ObjectTable& table, double size_assumed_m) {
  using nlohmann::json;
  json j;
  j["kind"] = id.kind();
  j["confidence"] = id.confidence();
  j["source"] = id.source();
  j["evidence"] = id.known() ? json(id.candidates.front().evidence) : json(nullptr);
  json candidates = json::array();
  for (std::size_t i = 0; i < id.candidates.size() && i < 5; ++i) {
    const KindGuess& g = id.candidates[i];
    candidates.push_back(
        {{"kind", g.kind}, {"confidence", g.confidence}, {"source", g.source}, {"evidence", g.evidence}});
  }
  j["candidates"] = candidates;
  j["notes"] = id.notes;
  j["warnings"] = id.warnings;
  const int k = id.known() ? table.find(id.kind()) : -1;
  if (k >= 0) {
    const ObjectKind& kind = table.kinds()[static_cast<std::size_t>(k)];
    j["group"] = kind.group;
    j["mass_range_kg"] = {kind.mass_kg[0], kind.mass_kg[1]};
    j["typical_longest_side_m"] = kind.typical_longest_side_m;
    j["structure"] = kind.structure;
  } else {
    j["mass_range_kg"] = nullptr;
  }
  j["size_assumed_m"] = size_assumed_m > 0 ? json(size_assumed_m) : json(nullptr);
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace g2p
