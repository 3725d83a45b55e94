// ObjectTable: the table of everyday object kinds (libg2p/data/objects.json),
// its checks, and free text matched against its terms.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/ascii.h"
#include "g2p/identify.h"
#include "identify/text_words.h"

namespace g2p {

extern const char* const kObjectTableJson[];  // generated from data/objects.json

using nlohmann::json;

namespace {

constexpr int kObjectTableVersion = 1;

Status field_error(const std::string& where, const std::string& kind, const std::string& what) {
  return Status::ParseError(where + ": kind '" + kind + "': " + what);
}

Result<std::array<double, 2>> read_range(const json& k, const char* key, const std::string& where,
                                         const std::string& name) {
  if (!k.contains(key) || !k[key].is_array() || k[key].size() != 2 || !k[key][0].is_number() || !k[key][1].is_number())
    return field_error(where, name, std::string("'") + key + "' must be [lo, hi], two numbers");
  const double lo = k[key][0].get<double>(), hi = k[key][1].get<double>();
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo > 0.0) || lo > hi)
    return field_error(where, name, std::string("'") + key + "' must hold 0 < lo <= hi");
  return std::array<double, 2>{lo, hi};
}

Result<ObjectKind> read_kind(const json& k, const std::string& where, std::size_t index) {
  ObjectKind kind;
  if (!k.is_object() || !k.contains("name") || !k["name"].is_string() || k["name"].get<std::string>().empty())
    return Status::ParseError(where + ": kinds[" + std::to_string(index) + "] needs a 'name'");
  kind.name = detail::lower_case(k["name"].get<std::string>());
  const std::string& n = kind.name;
  auto strings = [&](const char* key, std::vector<std::string>& out, bool required) -> Status {
    if (!k.contains(key)) return required ? field_error(where, n, std::string("needs '") + key + "'") : Status::Ok();
    if (!k[key].is_array()) return field_error(where, n, std::string("'") + key + "' must be a list of texts");
    for (const json& s : k[key]) {
      if (!s.is_string()) return field_error(where, n, std::string("'") + key + "' must be a list of texts");
      out.push_back(s.get<std::string>());
    }
    return Status::Ok();
  };
  if (k.contains("group") && k["group"].is_string()) kind.group = k["group"].get<std::string>();
  if (k.contains("coco") && k["coco"].is_string()) kind.coco = k["coco"].get<std::string>();
  G2P_RETURN_IF_ERROR(strings("synsets", kind.synsets, false));
  G2P_RETURN_IF_ERROR(strings("terms", kind.terms, false));
  Result<std::array<double, 2>> h = read_range(k, "height_m", where, n);
  if (!h.ok()) return h.status();
  Result<std::array<double, 2>> l = read_range(k, "longest_side_m", where, n);
  if (!l.ok()) return l.status();
  Result<std::array<double, 2>> m = read_range(k, "mass_kg", where, n);
  if (!m.ok()) return m.status();
  kind.height_m = *h;
  kind.longest_side_m = *l;
  kind.mass_kg = *m;
  if (!k.contains("typical") || !k["typical"].is_object() || !k["typical"].value("height_m", json()).is_number() ||
      !k["typical"].value("longest_side_m", json()).is_number())
    return field_error(where, n, "'typical' must give height_m and longest_side_m");
  kind.typical_height_m = k["typical"]["height_m"].get<double>();
  kind.typical_longest_side_m = k["typical"]["longest_side_m"].get<double>();
  if (!(kind.typical_height_m >= kind.height_m[0] && kind.typical_height_m <= kind.height_m[1]))
    return field_error(where, n, "typical height_m must lie in height_m");
  if (!(kind.typical_longest_side_m >= kind.longest_side_m[0] && kind.typical_longest_side_m <= kind.longest_side_m[1]))
    return field_error(where, n, "typical longest_side_m must lie in longest_side_m");
  kind.structure = k.value("structure", std::string("solid"));
  if (kind.structure != "solid" && kind.structure != "hollow" && kind.structure != "shell_with_contents")
    return field_error(where, n, "'structure' must be solid, hollow or shell_with_contents");
  if (k.contains("materials")) {
    if (!k["materials"].is_array()) return field_error(where, n, "'materials' must be a list");
    for (const json& m2 : k["materials"]) {
      if (!m2.is_object() || !m2.value("class", json()).is_string())
        return field_error(where, n, "each of 'materials' needs a 'class'");
      KindMaterial material{m2.value("role", std::string()), m2["class"].get<std::string>()};
      if (m2.contains("max_share")) {
        const json& share = m2["max_share"];
        if (!share.is_number() || !(share.get<double>() > 0.0 && share.get<double>() <= 1.0))
          return field_error(where, n, "a material's 'max_share' must be a number in (0, 1]");
        material.max_share = share.get<double>();
      }
      kind.materials.push_back(std::move(material));
    }
  }
  if (k.contains("hidden")) {
    if (!k["hidden"].is_array()) return field_error(where, n, "'hidden' must be a list");
    for (const json& x : k["hidden"]) {
      if (!x.is_object() || !x.value("mass_fraction", json()).is_number())
        return field_error(where, n, "each of 'hidden' needs a 'mass_fraction'");
      HiddenContent c{x.value("what", std::string()), x["mass_fraction"].get<double>(),
                      x.value("where", std::string("spread"))};
      if (!(c.mass_fraction >= 0.0 && c.mass_fraction <= 0.9))
        return field_error(where, n, "a hidden mass_fraction must lie in [0, 0.9]");
      kind.hidden.push_back(std::move(c));
    }
  }
  if (k.contains("sources") && k["sources"].is_object())
    for (const auto& [key, v] : k["sources"].items())
      if (v.is_string()) kind.sources[key] = v.get<std::string>();
  return kind;
}

// Levenshtein distance, for the nearest names.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace

Result<ObjectTable> ObjectTable::from_json(const std::string& text, const std::string& where) {
  // A field of the wrong JSON type (a number where a text belongs) throws
  // from nlohmann's value(); it is a parse error like any other.
  try {
    return parse_table(text, where);
  } catch (const json::exception&) {
    return Status::ParseError(where + ": a field holds the wrong kind of value (a number for a text, say)");
  }
}

Result<ObjectTable> ObjectTable::parse_table(const std::string& text, const std::string& where) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception&) {
    return Status::ParseError(where + ": not valid JSON");
  }
  if (!doc.is_object() || doc.value("format", std::string()) != "g2p-object-table")
    return Status::ParseError(where + ": 'format' must be \"g2p-object-table\"");
  if (!doc.value("version", json()).is_number_integer() || doc["version"].get<int>() != kObjectTableVersion)
    return Status::ParseError(where + ": 'version' must be " + std::to_string(kObjectTableVersion) +
                              " (this libg2p reads object tables of version " + std::to_string(kObjectTableVersion) +
                              ")");
  if (!doc.contains("kinds") || !doc["kinds"].is_array() || doc["kinds"].empty())
    return Status::ParseError(where + ": 'kinds' must be a non-empty list");
  ObjectTable table;
  table.wordnet_ = doc.value("wordnet", std::string());
  for (std::size_t i = 0; i < doc["kinds"].size(); ++i) {
    Result<ObjectKind> kind = read_kind(doc["kinds"][i], where, i);
    if (!kind.ok()) return kind.status();
    if (table.find(kind->name) >= 0) return Status::ParseError(where + ": kind '" + kind->name + "' appears twice");
    table.kinds_.push_back(std::move(*kind));
  }
  // Names first, so that a kind's own name is never another kind's term.
  for (std::size_t i = 0; i < table.kinds_.size(); ++i)
    table.term_kind_[detail::normalise_phrase(table.kinds_[i].name)] = static_cast<int>(i);
  for (std::size_t i = 0; i < table.kinds_.size(); ++i)
    for (const std::string& t : table.kinds_[i].terms)
      table.term_kind_.emplace(detail::normalise_phrase(t), static_cast<int>(i));
  return table;
}

Result<ObjectTable> ObjectTable::read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::IoError(path + ": cannot open the object table");
  std::stringstream ss;
  ss << in.rdbuf();
  return from_json(ss.str(), path);
}

const ObjectTable& ObjectTable::shipped() {
  static const ObjectTable* table = [] {
    std::string text;
    for (const char* const* chunk = kObjectTableJson; *chunk != nullptr; ++chunk) text += *chunk;
    Result<ObjectTable> t = from_json(text, "the shipped object table (libg2p/data/objects.json)");
    return new ObjectTable(t.ok() ? std::move(*t) : ObjectTable());  // checked by the tests; never destroyed
  }();
  return *table;
}

int ObjectTable::find(const std::string& name) const {
  const std::string n = detail::lower_case(name);
  for (std::size_t i = 0; i < kinds_.size(); ++i)
    if (kinds_[i].name == n) return static_cast<int>(i);
  return -1;
}

int ObjectTable::find_coco(const std::string& coco_class) const {
  for (std::size_t i = 0; i < kinds_.size(); ++i)
    if (!kinds_[i].coco.empty() && kinds_[i].coco == coco_class) return static_cast<int>(i);
  return -1;
}

std::vector<TextMatch> ObjectTable::match(const std::string& text) const {
  const std::vector<detail::Clause> clauses = detail::split_clauses(text);
  std::vector<TextMatch> found;
  for (std::size_t c = 0; c < clauses.size(); ++c) {
    const std::vector<std::string>& words = clauses[c];
    const int n = static_cast<int>(words.size());
    std::vector<bool> used(words.size(), false);
    for (int len = std::min(n, 5); len >= 1; --len) {
      for (int start = n - len; start >= 0; --start) {  // right to left: the head noun of a phrase comes last
        bool free = true;
        for (int w = start; w < start + len; ++w) free = free && !used[static_cast<std::size_t>(w)];
        if (!free) continue;
        std::vector<std::string> phrase(words.begin() + start, words.begin() + start + len);
        if (len == 1 && detail::is_generic_word(phrase[0])) continue;
        int kind = -1;
        std::string matched;
        for (const std::string& form : detail::singular_forms(phrase.back())) {
          phrase.back() = form;
          std::string key;
          for (const std::string& w : phrase) key += (key.empty() ? "" : " ") + w;
          const auto it = term_kind_.find(key);
          if (it != term_kind_.end()) {
            kind = it->second;
            matched = key;
            break;
          }
        }
        if (kind < 0) continue;
        for (int w = start; w < start + len; ++w) used[static_cast<std::size_t>(w)] = true;
        // An earlier clause, a longer phrase, then the later word in the clause.
        const double score = 100.0 - 30.0 * static_cast<double>(c) + 10.0 * len + double(start + len) / double(n);
        found.push_back({kind, matched, score});
      }
    }
  }
  std::sort(found.begin(), found.end(), [](const TextMatch& a, const TextMatch& b) { return a.score > b.score; });
  std::vector<TextMatch> out;
  std::set<int> seen;
  for (const TextMatch& m : found)
    if (seen.insert(m.kind).second) out.push_back(m);
  return out;
}

std::vector<std::string> ObjectTable::nearest(const std::string& text, int count) const {
  const std::string want = detail::normalise_phrase(text);
  std::vector<std::pair<double, int>> best(kinds_.size(), {1e9, 0});
  for (std::size_t i = 0; i < kinds_.size(); ++i) best[i].second = static_cast<int>(i);
  for (const auto& [term, kind] : term_kind_) {
    const double d =
        double(edit_distance(want, term)) / double(std::max<std::size_t>(1, std::max(want.size(), term.size())));
    std::pair<double, int>& b = best[static_cast<std::size_t>(kind)];
    b.first = std::min(b.first, d);
  }
  std::sort(best.begin(), best.end());
  std::vector<std::string> out;
  for (std::size_t i = 0; i < best.size() && static_cast<int>(out.size()) < count; ++i)
    out.push_back(kinds_[static_cast<std::size_t>(best[i].second)].name);
  return out;
}

}  // namespace g2p
