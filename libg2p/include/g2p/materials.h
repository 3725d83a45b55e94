// The material vocabulary: which classes a segmenter predicts and what each
// class means physically. The default is the Gen2Physics paper's 12 classes;
// a MaterialTable loaded from JSON replaces it for other vocabularies.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// Label of a face or pixel whose class is unknown (background, unseen, void).
inline constexpr int kUnknownLabel = -1;

// The paper's vocabulary, in its order; these are the default table's labels.
enum class PaperClass : int {
  kWood = 0,
  kRubber,
  kFabric,
  kOrganic,
  kLeather,
  kMetal,
  kPaper,
  kPlastic,
  kGlass,
  kCeramic,
  kStone,
  kOther,
};

enum class Structure { kSolid, kHollow };

G2P_API const char* to_string(Structure structure);  // "solid" / "hollow"

struct MaterialClass {
  std::string name;                                  // e.g. "Wood"; unique in a table (case-insensitive)
  std::array<std::uint8_t, 3> color{128, 128, 128};  // sRGB display colour of label renders
  double density_kg_m3 = 1000.0;                     // nominal density
  double density_min_kg_m3 = 1000.0;                 // plausible range, for mass ranges
  double density_max_kg_m3 = 1000.0;
  double friction_static = 0.5;  // Coulomb coefficients (dimensionless)
  double friction_dynamic = 0.5;
  double restitution = 0.5;                 // 0..1
  Structure structure = Structure::kSolid;  // default internal structure
  double wall_thickness_m = 0.002;          // used when the part is hollow
  double max_solid_thickness_m = 0.0;       // thickest plausible solid piece; 0 = no limit (docs/properties.md)
  double max_wall_thickness_m = 0.0;        // thickest plausible single wall; 0 = no limit (docs/properties.md)
  // The walls a hollow part of this class usually has, metres [thinnest,
  // thickest] (sheet metal 0.6-3 mm): the kind's mass posterior chooses among
  // them (posterior.h). {0, 0} = half to twice wall_thickness_m.
  std::array<double, 2> wall_range_m{0.0, 0.0};
  std::string source;  // where the values come from
};

class G2P_API MaterialTable {
 public:
  MaterialTable() = default;

  // The paper's 12 classes with libg2p's default values (docs/materials.md
  // lists their sources). Built once from the embedded data/materials.json.
  static const MaterialTable& paper_default();

  // Parses the JSON format documented in docs/materials.md. `origin` names the
  // text in error messages (a file path, say).
  static Result<MaterialTable> from_json(const std::string& json_text, const std::string& origin = "<json>");
  static Result<MaterialTable> load(const std::string& path);

  // Checks every class (unique names, positive densities inside their range,
  // friction >= 0, restitution in [0, 1], thickness > 0).
  static Result<MaterialTable> from_classes(std::vector<MaterialClass> classes, std::string name = "custom");

  std::string to_json() const;
  Status save(const std::string& path) const;

  const std::string& name() const { return name_; }
  int size() const { return static_cast<int>(classes_.size()); }
  const std::vector<MaterialClass>& classes() const { return classes_; }
  const MaterialClass& operator[](int label) const { return classes_[static_cast<std::size_t>(label)]; }
  bool valid_label(int label) const { return label >= 0 && label < size(); }

  // Label of the class called `name` (case-insensitive), or kUnknownLabel.
  int find(std::string_view name) const;

 private:
  std::string name_;
  std::vector<MaterialClass> classes_;
};

}  // namespace g2p
