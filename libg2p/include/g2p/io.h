// io: reading models (through assimp, privately) into libg2p's Model.
#pragma once

#include <cstddef>
#include <string>

#include "g2p/image.h"
#include "g2p/mesh.h"
#include "g2p/model.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

enum class UpAxis { kAuto, kX, kY, kZ };

struct ImportOptions {
  // Metres per file unit. 0 = from the format: glTF 1 (metres by specification),
  // FBX its UnitScaleFactor, everything else 1 (set it for millimetre STL files).
  double unit_scale = 0.0;
  // The object's real size, for files whose units cannot be trusted (image-to-3D
  // generators normalise every object to about a metre). 0 = keep the file's
  // size. At most one of the two, and not with unit_scale: the model is scaled
  // uniformly, after the up axis is resolved, so that its bounding box has...
  double height_m = 0.0;        // ...this extent along the up axis (g2p --height), or
  double longest_side_m = 0.0;  // ...this longest side (g2p --longest-side).
  // The file's up axis. kAuto: glTF/OBJ/PLY/FBX/DAE +Y (FBX: its UpAxis),
  // STL and 3MF +Z (CAD convention).
  UpAxis up_axis = UpAxis::kAuto;
  // Rotate so the file's up axis becomes +Z, libg2p's frame (as in MuJoCo,
  // URDF and SDF). False keeps the file's axes.
  bool z_up = true;
  // Decode base-colour and metallic-roughness textures (embedded or beside the file).
  bool load_textures = true;
  // Bounding-box diagonal after scaling must lie in [min_extent_m, max_extent_m];
  // outside it the file is almost certainly in other units and loading fails.
  double min_extent_m = 1e-4;  // 0.1 mm
  double max_extent_m = 1e4;   // 10 km
  // Reject files whose index or vertex arrays are inconsistent (indices out of
  // range, truncated arrays). False: drop the bad triangles with a warning.
  bool strict = true;
  // Refuse models with more triangles than this (memory guard).
  int max_faces = 50'000'000;
  // Parse the file in a child process, so that a crash inside assimp (the
  // parser) becomes a kParseError naming the fault instead of ending the
  // caller. Costs a fork and a copy of the parsed scene (docs/import.md).
  // False parses in this process (for debugging assimp, or where fork is
  // unwelcome).
  bool isolate_reader = true;
};

// Reads a model file: glTF/GLB, OBJ(+MTL), PLY, STL, FBX, DAE, 3MF and the
// other formats assimp reads. Node transforms are applied and all meshes merged
// into Model::mesh with per-face provenance. Polygons are triangulated; every
// triangle keeps the index of the polygon it came from.
G2P_API Result<Model> load_model(const std::string& path, const ImportOptions& options = {});

// Same, from bytes in memory. `format_hint` is a file extension ("glb", "obj").
// External references (.bin, textures) cannot be resolved from memory.
G2P_API Result<Model> load_model_from_memory(const void* data, std::size_t size, const std::string& format_hint,
                                             const ImportOptions& options = {});

// What was read, as `g2p info` shows it: the file, its frame, meshes, faces,
// bounds, area and every source material with its face count, PBR values and
// textures, and the import's warnings. Text (lines ending in a newline) and
// JSON (indented, without a final newline).
G2P_API std::string model_summary_text(const Model& model);
G2P_API std::string model_summary_json(const Model& model);

// Writes a mesh's triangles by extension: .obj (text), .ply (binary
// little-endian) or .stl (binary), in metres. Written under a temporary name
// and renamed, so an existing file is never left half-overwritten.
G2P_API Status write_mesh(const std::string& path, const Mesh& mesh);

// Metres per unit for a unit name: "m", "cm", "mm", "in", "ft" (and long forms),
// or a positive number of metres per unit ("0.001").
G2P_API Result<double> parse_unit(const std::string& unit);

// Reads an image file (PNG, JPEG, WebP, BMP or TIFF, told by its bytes) as 8-bit RGBA.
G2P_API Result<ImageU8> read_image(const std::string& path);

// Writes an 8-bit image with 1 (grey), 3 (RGB) or 4 (RGBA) channels; the
// format follows the extension: .png, .jpg or .jpeg (quality 95, no alpha), .bmp. Written to a temporary name and
// renamed, so an existing file is never left half-overwritten.
G2P_API Status write_image(const std::string& path, const ImageU8& image);

// Writes a text (or any byte) file under a temporary name and renames it, so
// an existing file is never left half-overwritten.
G2P_API Status write_text_file(const std::string& path, const std::string& text);

// Whether assimp can read files with this extension (with or without the dot).
G2P_API bool is_supported_extension(const std::string& extension);

}  // namespace g2p
