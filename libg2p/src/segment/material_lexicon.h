// Private: material words in several languages, for name evidence.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "g2p/materials.h"

namespace g2p::detail {

// Lower-case words of a name: split at non-letters and camelCase boundaries,
// accents of Latin-1 letters folded ("SheenChair_wood2" -> sheen, chair, wood).
std::vector<std::string> tokenize(std::string_view text);

// Per class of `table`, how strongly `text` names that class's material (0 =
// not at all, 1 = a material word). Classes are matched by their English names
// (the paper's vocabulary); a custom class is also matched by its own name.
std::vector<float> name_evidence(std::string_view text, const MaterialTable& table);

}  // namespace g2p::detail
