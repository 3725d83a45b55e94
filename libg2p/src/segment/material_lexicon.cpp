// Material words and their classes, for the `pbr` segmenter's name evidence.
//
// Asset authors name materials and meshes after what they are made of ("oak",
// "chrome_legs", "Stoff_blau"), so names are the strongest evidence an asset
// carries when present. The lexicon covers English, German, French, Spanish,
// Italian, Portuguese and Dutch material words, common species and alloys, and
// a few object words that nearly always imply one material (cushion -> Fabric,
// tyre -> Rubber), the latter at lower strength. Words that mislead more often
// than they help are left out on purpose: "skin" (a texture term in games),
// "gold"/"silver" as colours are kept as Metal only at lower strength, "china"
// (a country as often as porcelain), "board" (wood, paper or circuit).
#include "segment/material_lexicon.h"

#include "g2p/segment.h"

#include <algorithm>
#include <cctype>

namespace g2p::detail {
namespace {

struct Entry {
  const char* word;
  const char* class_name;
  float strength;  // 1 = the word names the material; lower = an object or colour word that suggests it
};

// clang-format off
const Entry kLexicon[] = {
  // Wood
  {"wood", "Wood", 1}, {"wooden", "Wood", 1}, {"timber", "Wood", 1}, {"lumber", "Wood", 1},
  {"plywood", "Wood", 1}, {"mdf", "Wood", 1}, {"veneer", "Wood", 1}, {"oak", "Wood", 1},
  {"walnut", "Wood", 1}, {"pine", "Wood", 1}, {"maple", "Wood", 1}, {"birch", "Wood", 1},
  {"beech", "Wood", 1}, {"mahogany", "Wood", 1}, {"teak", "Wood", 1}, {"cedar", "Wood", 1},
  {"ebony", "Wood", 1}, {"bamboo", "Wood", 0.8f}, {"rattan", "Wood", 0.7f}, {"wicker", "Wood", 0.7f},
  {"parquet", "Wood", 1}, {"holz", "Wood", 1}, {"eiche", "Wood", 1}, {"buche", "Wood", 1},
  {"bois", "Wood", 1}, {"chene", "Wood", 1}, {"madera", "Wood", 1}, {"roble", "Wood", 1},
  {"legno", "Wood", 1}, {"rovere", "Wood", 1}, {"madeira", "Wood", 1}, {"hout", "Wood", 1},
  // Metal
  {"metal", "Metal", 1}, {"metallic", "Metal", 1}, {"steel", "Metal", 1}, {"stainless", "Metal", 1},
  {"chrome", "Metal", 1}, {"chromed", "Metal", 1}, {"brass", "Metal", 1}, {"bronze", "Metal", 1},
  {"copper", "Metal", 1}, {"aluminium", "Metal", 1}, {"aluminum", "Metal", 1}, {"alu", "Metal", 0.8f},
  {"iron", "Metal", 1}, {"nickel", "Metal", 1}, {"zinc", "Metal", 1}, {"titanium", "Metal", 1},
  {"pewter", "Metal", 1}, {"gold", "Metal", 0.6f}, {"golden", "Metal", 0.5f}, {"silver", "Metal", 0.6f},
  {"metall", "Metal", 1}, {"stahl", "Metal", 1}, {"eisen", "Metal", 1}, {"messing", "Metal", 1},
  {"acier", "Metal", 1}, {"fer", "Metal", 0.8f}, {"laiton", "Metal", 1}, {"acero", "Metal", 1},
  {"hierro", "Metal", 1}, {"metallo", "Metal", 1}, {"acciaio", "Metal", 1}, {"ferro", "Metal", 1},
  {"ottone", "Metal", 1}, {"cobre", "Metal", 1}, {"rame", "Metal", 1}, {"staal", "Metal", 1},
  // Fabric
  {"fabric", "Fabric", 1}, {"cloth", "Fabric", 1}, {"textile", "Fabric", 1}, {"velvet", "Fabric", 1},
  {"cotton", "Fabric", 1}, {"linen", "Fabric", 1}, {"wool", "Fabric", 1}, {"silk", "Fabric", 1},
  {"polyester", "Fabric", 1}, {"denim", "Fabric", 1}, {"canvas", "Fabric", 0.8f}, {"felt", "Fabric", 0.9f},
  {"tweed", "Fabric", 1}, {"chenille", "Fabric", 1}, {"boucle", "Fabric", 1}, {"knit", "Fabric", 1},
  {"upholstery", "Fabric", 1}, {"carpet", "Fabric", 0.9f}, {"rug", "Fabric", 0.8f}, {"cushion", "Fabric", 0.7f},
  {"pillow", "Fabric", 0.7f}, {"curtain", "Fabric", 0.7f}, {"sheen", "Fabric", 0.4f}, {"stoff", "Fabric", 1},
  {"samt", "Fabric", 1}, {"tissu", "Fabric", 1}, {"velours", "Fabric", 1}, {"tela", "Fabric", 1},
  {"tessuto", "Fabric", 1}, {"velluto", "Fabric", 1}, {"tecido", "Fabric", 1}, {"stof", "Fabric", 1},
  // Leather
  {"leather", "Leather", 1}, {"suede", "Leather", 1}, {"nubuck", "Leather", 1}, {"hide", "Leather", 0.7f},
  {"leder", "Leather", 1}, {"cuir", "Leather", 1}, {"cuero", "Leather", 1}, {"pelle", "Leather", 1},
  {"couro", "Leather", 1}, {"leer", "Leather", 0.8f},
  // Glass
  {"glass", "Glass", 1}, {"glazing", "Glass", 1}, {"crystal", "Glass", 0.8f}, {"window", "Glass", 0.6f},
  {"mirror", "Glass", 0.7f}, {"lens", "Glass", 0.7f}, {"glas", "Glass", 1}, {"verre", "Glass", 1},
  {"vidrio", "Glass", 1}, {"vetro", "Glass", 1}, {"vidro", "Glass", 1},
  // Ceramic
  {"ceramic", "Ceramic", 1}, {"ceramics", "Ceramic", 1}, {"porcelain", "Ceramic", 1},
  {"stoneware", "Ceramic", 1}, {"earthenware", "Ceramic", 1}, {"terracotta", "Ceramic", 1},
  {"clay", "Ceramic", 0.8f}, {"tile", "Ceramic", 0.6f}, {"tiles", "Ceramic", 0.6f}, {"enamel", "Ceramic", 0.6f},
  {"keramik", "Ceramic", 1}, {"porzellan", "Ceramic", 1}, {"ceramique", "Ceramic", 1},
  {"ceramica", "Ceramic", 1}, {"porcelana", "Ceramic", 1}, {"porcellana", "Ceramic", 1},
  // Stone
  {"stone", "Stone", 1}, {"marble", "Stone", 1}, {"granite", "Stone", 1}, {"concrete", "Stone", 1},
  {"cement", "Stone", 1}, {"slate", "Stone", 1}, {"rock", "Stone", 0.8f}, {"brick", "Stone", 1},
  {"limestone", "Stone", 1}, {"travertine", "Stone", 1}, {"quartz", "Stone", 0.8f}, {"terrazzo", "Stone", 1},
  {"plaster", "Stone", 0.7f}, {"stein", "Stone", 1}, {"marmor", "Stone", 1}, {"beton", "Stone", 1},
  {"pierre", "Stone", 1}, {"marbre", "Stone", 1}, {"piedra", "Stone", 1}, {"marmol", "Stone", 1},
  {"pietra", "Stone", 1}, {"marmo", "Stone", 1}, {"pedra", "Stone", 1}, {"steen", "Stone", 1},
  // Plastic
  {"plastic", "Plastic", 1}, {"plastics", "Plastic", 1}, {"polymer", "Plastic", 1}, {"pvc", "Plastic", 1},
  {"abs", "Plastic", 0.8f}, {"acrylic", "Plastic", 0.9f}, {"nylon", "Plastic", 0.8f}, {"vinyl", "Plastic", 0.9f},
  {"polypropylene", "Plastic", 1}, {"polyethylene", "Plastic", 1}, {"polycarbonate", "Plastic", 1},
  {"resin", "Plastic", 0.8f}, {"epoxy", "Plastic", 0.8f}, {"plexiglass", "Plastic", 0.8f},
  {"kunststoff", "Plastic", 1}, {"plastik", "Plastic", 1}, {"plastique", "Plastic", 1},
  {"plastico", "Plastic", 1}, {"plastica", "Plastic", 1},
  // Rubber
  {"rubber", "Rubber", 1}, {"latex", "Rubber", 1}, {"silicone", "Rubber", 0.9f}, {"neoprene", "Rubber", 1},
  {"tire", "Rubber", 0.8f}, {"tyre", "Rubber", 0.8f}, {"gummi", "Rubber", 1}, {"caoutchouc", "Rubber", 1},
  {"goma", "Rubber", 1}, {"gomma", "Rubber", 1}, {"borracha", "Rubber", 1},
  // Paper
  {"paper", "Paper", 1}, {"cardboard", "Paper", 1}, {"carton", "Paper", 0.9f}, {"paperboard", "Paper", 1},
  {"label", "Paper", 0.6f}, {"sticker", "Paper", 0.7f}, {"book", "Paper", 0.6f}, {"papier", "Paper", 1},
  {"pappe", "Paper", 1}, {"karton", "Paper", 1}, {"papel", "Paper", 1}, {"carta", "Paper", 0.8f},
  // Organic
  {"organic", "Organic", 1}, {"food", "Organic", 0.9f}, {"fruit", "Organic", 1}, {"vegetable", "Organic", 1},
  {"plant", "Organic", 0.9f}, {"leaf", "Organic", 1}, {"leaves", "Organic", 1}, {"flower", "Organic", 0.9f},
  {"petal", "Organic", 1}, {"bread", "Organic", 1}, {"avocado", "Organic", 1}, {"apple", "Organic", 1},
  {"banana", "Organic", 1}, {"lemon", "Organic", 1}, {"tomato", "Organic", 1}, {"potato", "Organic", 1},
  {"meat", "Organic", 1}, {"cheese", "Organic", 1}, {"egg", "Organic", 0.8f}, {"moss", "Organic", 1},
  {"grass", "Organic", 1}, {"soil", "Organic", 0.8f}, {"bark", "Organic", 0.6f},
  // Other: wax, foams, sponges and the like
  {"wax", "Other", 1}, {"candle", "Other", 0.7f}, {"foam", "Other", 0.6f}, {"sponge", "Other", 0.8f},
};
// clang-format on

// Folds the accented letters of the lexicon's languages (UTF-8, two bytes)
// to ASCII, so "chêne" and "mármol" match "chene" and "marmol".
std::string fold(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == 0xC3 && i + 1 < text.size()) {
      if (static_cast<unsigned char>(text[i + 1]) == 0x9F) {  // sharp s
        out += "ss";
        ++i;
        continue;
      }
      const auto d = static_cast<unsigned char>(text[++i]) | 0x20;  // lower case
      const char* map = "aaaaaaaceeeeiiiidnooooo/ouuuuyty";         // U+00E0..U+00FF
      if (d >= 0xA0) out.push_back(map[d - 0xA0]);
      continue;
    }
    out.push_back(static_cast<char>(c));
  }
  return out;
}

}  // namespace

std::vector<std::string> tokenize(std::string_view text) {
  const std::string folded = fold(text);
  std::vector<std::string> tokens;
  std::string current;
  auto flush = [&] {
    if (!current.empty()) tokens.push_back(current);
    current.clear();
  };
  for (std::size_t i = 0; i < folded.size(); ++i) {
    const char c = folded[i];
    if (!std::isalpha(static_cast<unsigned char>(c))) {  // digits and punctuation separate words
      flush();
      continue;
    }
    // camelCase: a capital after a lower-case letter starts a word ("SheenChair").
    if (std::isupper(static_cast<unsigned char>(c)) && !current.empty() &&
        std::islower(static_cast<unsigned char>(folded[i - 1])))
      flush();
    current.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  }
  flush();
  return tokens;
}

std::vector<float> name_evidence(std::string_view text, const MaterialTable& table) {
  std::vector<float> evidence(static_cast<std::size_t>(table.size()), 0.f);
  for (const std::string& token : tokenize(text)) {
    for (const Entry& e : kLexicon) {
      const std::string_view word(e.word);
      float s = 0.f;
      if (token == word) s = e.strength;
      // Compounds ("woodgrain", "eichenholz"): long words inside longer tokens, weaker.
      else if (word.size() >= 5 && token.size() > word.size() && token.find(word) != std::string::npos)
        s = 0.8f * e.strength;
      if (s <= 0.f) continue;
      const int label = table.find(e.class_name);
      if (label != kUnknownLabel) evidence[static_cast<std::size_t>(label)] = std::max(evidence[label], s);
    }
    // A class of a custom vocabulary named in the text counts as itself.
    const int own = table.find(token);
    if (own != kUnknownLabel) evidence[static_cast<std::size_t>(own)] = std::max(evidence[own], 1.f);
  }
  return evidence;
}

bool is_placeholder_name(std::string_view text, PlaceholderKind kind) {
  // Default words of Blender (Cube, Material.001, Collection, Grid), Maya
  // (pCubeShape1, polySurface1, lambert2SG, initialShadingGroup,
  // aiStandardSurface), 3ds Max (Box001, "01 - Default"), SketchUp
  // (Color_A01, ID123), assimp (DefaultMaterial, defaultobject, $RootNode,
  // nodes[0], meshes[0]), trimesh and the generators' files (geometry_0,
  // material_0, world, tmpoxykr9_1.ply) and libg2p's own --anonymize-names
  // (material_0, mesh_0, node, texture_0).
  static constexpr std::string_view kWords =
      " ai armature blinn box circle collection color colour cone cube cylinder dae data default defaultmaterial"
      " defaultobject empty export exported fbx geom geometry glb gltf grid group ico icosphere id initial instance"
      " lambert mat material materials mesh meshes model mtl new node nodes none noname null obj object phong plane"
      " ply poly prim primitive root scene sg shading shape sketchup sphere standard stl submesh surface torus"
      " transform untitled unnamed uv world ";
  // Words that say nothing only in a texture file's name (baseColor.png,
  // texture_0_diffuse.jpg); as a part's name, "Base" or "Map" is a word.
  static constexpr std::string_view kTextureWords = " albedo base diffuse image img map tex texture ";
  const std::string folded = fold(text);
  // A script tokenize does not read (Cyrillic, Greek, CJK) is somebody's word.
  if (std::any_of(folded.begin(), folded.end(), [](char c) { return static_cast<unsigned char>(c) >= 0x80; }))
    return false;
  // 3ds Max names an object after its wireframe colour: wire_ and nine digits.
  constexpr std::string_view kWire = "wire_";
  const auto digit = [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; };
  if (folded.size() == kWire.size() + 9 &&
      std::equal(kWire.begin(), kWire.end(), folded.begin(),
                 [](char w, char c) { return w == std::tolower(static_cast<unsigned char>(c)); }) &&
      std::all_of(folded.begin() + kWire.size(), folded.end(), digit))
    return true;
  for (const std::string& token : tokenize(folded)) {  // folded is ASCII here: folding again changes nothing
    if (token.size() <= 1) continue;
    if (token.compare(0, 3, "tmp") == 0) continue;  // a temporary file's name (Python's tempfile)
    const std::string word = " " + token + " ";
    const bool known = kWords.find(word) != std::string_view::npos ||
                       (kind == PlaceholderKind::kTextureFile && kTextureWords.find(word) != std::string_view::npos);
    if (!known) return false;
  }
  return true;
}

}  // namespace g2p::detail

namespace g2p {

std::vector<float> material_name_evidence(std::string_view name, const MaterialTable& table) {
  return detail::name_evidence(name, table);
}

bool is_placeholder_name(std::string_view name) { return detail::is_placeholder_name(name); }

}  // namespace g2p
