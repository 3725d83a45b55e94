// Private: the words of a text as the object table matches them (file names,
// node names, a user's description).
#pragma once

#include <string>
#include <vector>

namespace g2p::detail {

using Clause = std::vector<std::string>;  // lowercase words

// Lowercase words, split at spaces, punctuation, camelCase ("SheenChair") and
// digit runs ("chair01" -> chair, 01); letters outside ASCII stay in words.
std::vector<std::string> split_words(const std::string& text);
// The words joined by single spaces: the form terms are stored and looked up in.
std::string normalise_phrase(const std::string& text);
// The words in clauses: a new clause starts after a comma, semicolon or a
// linking word ("with", "of", "on", "and", ...), which is dropped.
std::vector<Clause> split_clauses(const std::string& text);
// Words that name no object in a file ("mesh", "model", "material", "sample").
bool is_generic_word(const std::string& word);
// The word itself, then its singular readings, the plain plural first
// ("panes" -> pane, pan; "benches" -> benche, bench; "knives" -> knife).
std::vector<std::string> singular_forms(const std::string& word);

}  // namespace g2p::detail
