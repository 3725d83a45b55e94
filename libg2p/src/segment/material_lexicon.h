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

// Whether `text` is a placeholder: every word of it (tokenize) is one that
// exporters, modelling tools and image-to-3D pipelines give when nobody named
// anything ("Material.001", "material_0", "Cube", "pCubeShape1", "mesh_3",
// "nodes[0]", "01 - Default", "geometry_0", "wire_028089177"), or a single
// letter; an empty or all-digit text is one too. A curated asset's own words
// ("potty", "black", "Wood_bareoak"), and any text in a script other than
// Latin, are not. A texture file's name may also use the words of a texture
// ("texture_0", "baseColor", "diffuse"), which name a part elsewhere ("Base").
enum class PlaceholderKind { kName, kTextureFile };
bool is_placeholder_name(std::string_view text, PlaceholderKind kind = PlaceholderKind::kName);

}  // namespace g2p::detail
