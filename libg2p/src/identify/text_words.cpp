// The words of a text as the object table matches them.
#include "identify/text_words.h"

#include <algorithm>
#include <cctype>
#include <set>

namespace g2p::detail {
namespace {

bool is_alpha(unsigned char c) { return std::isalpha(c) != 0 || c >= 0x80; }
bool is_digit(unsigned char c) { return std::isdigit(c) != 0; }

// Words after which a new clause starts: "a chair with metal legs" names a
// chair first.
const std::set<std::string>& linking_words() {
  static const std::set<std::string> words{"with",   "of",    "on",   "in",     "for",     "from", "and",
                                           "or",     "under", "over", "beside", "by",      "at",   "near",
                                           "behind", "into",  "onto", "to",     "without", "plus", "inside"};
  return words;
}

}  // namespace

std::vector<std::string> split_words(const std::string& text) {
  std::vector<std::string> words;
  std::string word;
  auto flush = [&] {
    if (!word.empty()) words.push_back(word);
    word.clear();
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (!is_alpha(c) && !is_digit(c)) {
      flush();
      if (c == ',' || c == ';') words.emplace_back(",");  // a clause mark for split_clauses
      continue;
    }
    if (!word.empty()) {
      const unsigned char prev = static_cast<unsigned char>(text[i - 1]);
      const bool camel = std::isupper(c) != 0 && std::islower(prev) != 0;
      const bool digit_edge = is_digit(c) != is_digit(prev);
      if (camel || digit_edge) flush();
    }
    word += static_cast<char>(c < 0x80 ? std::tolower(c) : c);
  }
  flush();
  return words;
}

std::string normalise_phrase(const std::string& text) {
  std::string out;
  for (const std::string& w : split_words(text)) {
    if (w == ",") continue;
    out += (out.empty() ? "" : " ") + w;
  }
  return out;
}

std::vector<Clause> split_clauses(const std::string& text) {
  std::vector<Clause> clauses(1);
  for (const std::string& w : split_words(text)) {
    if (w == "," || linking_words().count(w) > 0) {
      if (!clauses.back().empty()) clauses.emplace_back();
      continue;
    }
    clauses.back().push_back(w);
  }
  if (clauses.back().empty() && clauses.size() > 1) clauses.pop_back();
  return clauses;
}

bool is_generic_word(const std::string& word) {
  static const std::set<std::string> generic{
      "model",    "mesh",  "object", "sample", "output",    "scene",  "material", "texture",   "textured", "default",
      "untitled", "node",  "root",   "group",  "part",      "body",   "base",     "geometry",  "final",    "low",
      "high",     "poly",  "lod",    "color",  "colour",    "main",   "new",      "copy",      "test",     "export",
      "asset",    "item",  "thing",  "shape",  "obj",       "glb",    "gltf",     "fbx",       "top",      "bottom",
      "side",     "front", "back",   "left",   "right",     "inner",  "outer",    "mat",       "tex",      "image",
      "a",        "an",    "the",    "my",     "generated", "result", "instance", "primitive", "submesh",  "piece"};
  return generic.count(word) > 0 ||
         std::all_of(word.begin(), word.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; });
}

std::vector<std::string> singular_forms(const std::string& w) {
  std::vector<std::string> forms{w};
  const auto ends = [&](const char* s) {
    const std::string suffix(s);
    return w.size() > suffix.size() + 1 && w.compare(w.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  // The plain plural first: "panes" is a pane before it is a pan.
  if (ends("s") && !ends("ss")) forms.push_back(w.substr(0, w.size() - 1));
  if (ends("ies")) forms.push_back(w.substr(0, w.size() - 3) + "y");
  if (ends("ves")) {
    forms.push_back(w.substr(0, w.size() - 3) + "f");
    forms.push_back(w.substr(0, w.size() - 3) + "fe");
  }
  // "-es" only after a hiss or an o (boxes, glasses, benches, dishes,
  // tomatoes): "panes" is no pan.
  if (ends("es") && (ends("ses") || ends("xes") || ends("zes") || ends("ches") || ends("shes") || ends("oes")))
    forms.push_back(w.substr(0, w.size() - 2));
  return forms;
}

}  // namespace g2p::detail
