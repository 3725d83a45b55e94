// Private: factories of the built-in segmenters, registered by name in
// segmenter_registry().
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/model_files.h"
#include "g2p/segment.h"

namespace g2p {

std::unique_ptr<Segmenter> make_pbr_segmenter();
std::unique_ptr<Segmenter> make_onnx_segmenter();
std::unique_ptr<Segmenter> make_oracle_segmenter();
std::unique_ptr<Segmenter> make_learned_segmenter();
std::unique_ptr<Segmenter> make_auto_segmenter();
std::unique_ptr<Segmenter> make_hybrid_segmenter();

namespace detail {

// The `onnx` backend with its network loaded by the first set_model instead of
// by configure, which still reads and checks the card and that the network
// file exists. `learned` and `auto` use it: a model that `pbr` labels alone
// then costs neither the load (about 0.2 s for the shipped network) nor its
// memory.
std::unique_ptr<Segmenter> make_deferred_onnx_segmenter();

// `pbr`'s class score per unit of name evidence in a material's name.
inline constexpr float kPbrNameWeight = 4.f;

// The name evidence the `pbr` backend adds to its class scores, in its score
// units, per class of the table: per source material, 4 x the evidence of its
// name and its textures' file names (a prefix all material names share counts
// a quarter); per source mesh, 0.7 of that weight for the mesh and node names
// (same prefix rule). `learned` reads it to decide where names speak.
struct NameScores {
  std::vector<std::vector<float>> material;  // [material][class]
  std::vector<std::vector<float>> mesh;      // [source mesh][class]; empty rows for meshes no primitive names
};
NameScores pbr_name_scores(const Model& model, const MaterialTable& table);

// The card of the network libg2p ships (g2p-materials.json where
// shipped_model_file looks), or "" when none is found.
std::string shipped_model_card();
// shipped_model_file (core/model_files.h): a file beside the network.

// Whether an author set the material's PBR values: read from a format with PBR
// materials, and not glTF's defaults (a metallic-roughness texture,
// transmission, or metallic/roughness other than (1, 1)). An OBJ's metallic 0
// and roughness from its Phong exponent are the importer's, not evidence.
bool pbr_authored(const SourceMaterial& material);

// Per face (empty without face provenance): its names name a class, read as
// `pbr` reads them (pbr_name_scores): its material's and its mesh's scores
// summed, one class reaching kPbrNameWeight x `threshold` and no other above
// kPbrNameWeight x 0.5.
std::vector<char> faces_named(const Model& model, const MaterialTable& table, double threshold);

}  // namespace detail

}  // namespace g2p
