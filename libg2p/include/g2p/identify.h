// identify: what the object is (a chair, a car, a refrigerator), from the
// user's words, the names in the file and the rendered views. Not a stage of
// the Gen2Physics paper, whose vision-language model sees the object in every
// prompt; libg2p asks once, after render, so that a mesh without a real size
// (image-to-3D meshes come normalised to about a metre) can be given its
// kind's typical size and its mass checked against its kind's usual range
// (docs/identify.md). Backends are swappable through identifier_registry().
//
//   g2p::IdentifyInput in;
//   in.model = &model;  in.views = &views;  in.object_text = "exercise bike";
//   g2p::Result<g2p::Identification> id = g2p::identify(in);   // "auto"
//   if (id.ok() && id->known()) std::printf("%s\n", id->kind().c_str());
#pragma once

#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "g2p/complete.h"
#include "g2p/materials.h"
#include "g2p/mesh.h"
#include "g2p/model.h"
#include "g2p/project.h"
#include "g2p/properties.h"
#include "g2p/registry.h"
#include "g2p/render.h"
#include "g2p/status.h"
#include "g2p/visibility.h"
#include "g2p/vlm.h"

namespace g2p {

// ---- The table of everyday object kinds ----------------------------------------
// libg2p/data/objects.json (format "g2p-object-table", its card objects.md and
// schema objects.schema.json beside it), built by scripts/objects/build_objects.py
// from hand-written facts with sources and Debian's WordNet 3.0.

struct KindMaterial {
  std::string role;            // "frame", "seat", "tyres", ...
  std::string material_class;  // a class of the paper's table: "Wood", "Metal", ...
  // The most of the object's surface this role covers (a car's tyres, 0.2);
  // 0 = not given (posterior.h's defaults apply).
  double max_share = 0.0;
};

// Mass that no surface shows: a refrigerator's compressor, a bike's flywheel.
struct HiddenContent {
  std::string what;            // in words
  double mass_fraction = 0.0;  // of the whole object's mass, [0, 0.9]
  std::string where;           // "bottom", "centre" or "spread"
};

struct ObjectKind {
  std::string name;                                // "chair": what g2p prints and --object takes
  std::string group;                               // "furniture", "appliance", "vehicle", ...
  std::vector<std::string> synsets;                // WordNet 3.0 noun senses, "chair.n.01"
  std::string coco;                                // the COCO class this kind answers for; "" = none
  std::vector<std::string> terms;                  // lowercase words and phrases that name it (WordNet lemmas and more)
  std::array<double, 2> height_m{0.0, 0.0};        // usual height, upright, metres [lo, hi]
  std::array<double, 2> longest_side_m{0.0, 0.0};  // usual longest side, metres [lo, hi]
  double typical_height_m = 0.0;                   // the size assumed when a mesh has none
  double typical_longest_side_m = 0.0;
  std::array<double, 2> mass_kg{0.0, 0.0};  // plausible total mass of a real one, kg [lo, hi]
  std::string structure;                    // "solid", "hollow" or "shell_with_contents"
  std::vector<KindMaterial> materials;      // by role, the main one first
  std::vector<HiddenContent> hidden;
  std::map<std::string, std::string> sources;  // "size", "mass", "materials", "hidden": where each figure comes from
};

// One place where a text names a kind.
struct TextMatch {
  int kind = -1;     // index into ObjectTable::kinds()
  std::string term;  // the words that matched ("exercise bike")
  double score = 0;  // higher is better: longer phrases, earlier clauses, head nouns
};

class G2P_API ObjectTable {
 public:
  // Reads and checks a table; `where` names it in errors (a file path).
  static Result<ObjectTable> from_json(const std::string& text, const std::string& where = "object table");
  static Result<ObjectTable> read(const std::string& path);
  // The table libg2p ships (compiled in).
  static const ObjectTable& shipped();

  const std::vector<ObjectKind>& kinds() const { return kinds_; }
  int size() const { return static_cast<int>(kinds_.size()); }
  const std::string& wordnet() const { return wordnet_; }  // the WordNet the terms came from
  // The kind named exactly `name` (a kind's name, case-insensitive), or -1.
  int find(const std::string& name) const;
  // The kind that answers for a COCO class ("dining table"), or -1.
  int find_coco(const std::string& coco_class) const;
  // The kinds a free text names ("a wooden chair with metal legs", a file
  // name such as "OfficeChair_01"), best first, one match per kind. Words are
  // split at spaces, punctuation, digits and camelCase, plurals are read as
  // singulars, and the longest phrase wins where phrases overlap; a match in
  // the first clause (before "with", "of", "on", ...) and the last noun of a
  // phrase rank first.
  std::vector<TextMatch> match(const std::string& text) const;
  // Kind names nearest to `text` by spelling (edit distance over names and
  // terms), for an error that offers what the user may have meant.
  std::vector<std::string> nearest(const std::string& text, int count = 5) const;

 private:
  static Result<ObjectTable> parse_table(const std::string& text, const std::string& where);
  std::vector<ObjectKind> kinds_;
  std::map<std::string, int> term_kind_;  // every term and name -> kind
  std::string wordnet_;
};

// ---- Identification -------------------------------------------------------------

// One candidate kind, from one source or several.
struct KindGuess {
  std::string kind;         // an ObjectTable kind's name
  double confidence = 0.0;  // [0, 1]
  std::string source;       // "object" (the user's words), "names", "detector", "vlm", "override", or joined with '+'
  std::string evidence;     // in words: "file name 'SheenChair'", "chair in 9 of 11 views"
};

struct Identification {
  std::vector<KindGuess> candidates;  // best first; empty or below kKnownConfidence = unknown
  std::vector<std::string> notes;     // what each source said, conflicts between them
  std::vector<std::string> warnings;  // sources that could not run (a missing model file), in words

  static constexpr double kKnownConfidence = 0.25;  // below it the object is "unknown"
  bool known() const { return !candidates.empty() && candidates.front().confidence >= kKnownConfidence; }
  // The best kind's name, or "unknown".
  std::string kind() const { return known() ? candidates.front().kind : std::string("unknown"); }
  double confidence() const { return candidates.empty() ? 0.0 : candidates.front().confidence; }
  std::string source() const { return known() ? candidates.front().source : std::string(); }
};

// What an identifier may look at. All must outlive the call; every pointer
// but `model` and `table` may be null.
struct IdentifyInput {
  const Model* model = nullptr;              // its names: meshes, nodes, materials, the file's
  const std::vector<View>* views = nullptr;  // rendered views (RGB) for detectors and the vlm
  // The model's renderer, set_model(*model) done: backends that see better in
  // views of their own (the detector's eye-level turntable) render them.
  const Renderer* renderer = nullptr;
  const ObjectTable* table = nullptr;  // null: ObjectTable::shipped()
  std::string object_text;             // the user's words (g2p run --object "exercise bike"); "" = none
  bool use_file_name = true;           // false when names were removed (anonymize_names)
};

class G2P_API Identifier {
 public:
  virtual ~Identifier();
  // This backend's settings bound to this instance (settings.h): info()
  // lists them with their values, apply() sets them. Default: none.
  virtual SettingsSpec settings();
  // Applies settings, all or none: a bad key or value leaves the backend as it
  // was. Default: settings().apply(); a backend overrides it only to act on
  // the new values (load a network, make a client).
  virtual Status configure(const BackendSettings& settings);
  // An unknown object is not an error: it is an Identification with no
  // candidate. Errors are for input the backend cannot use at all (the
  // user's words that match no kind: kNotFound naming the nearest kinds).
  virtual Result<Identification> identify(const IdentifyInput& input) const = 0;
};

// Backends by name. libg2p registers:
//   "auto"     (the default) the user's words when given, which win; else the
//              names, the detector and the classifier together (settings
//              detector, classifier = on|off), conflicts noted;
//   "object"   the user's words only (IdentifyInput::object_text);
//   "names"    the file, node, mesh and material names, matched through the
//              table's WordNet terms;
//   "detector" NanoDet-g's COCO detector over views of the object (the shipped
//              g2p-objects-nanodet.onnx; settings model_card, min_score,
//              min_iou, views = turntable (its own eye-level views, with a
//              renderer) or given (IdentifyInput::views));
//   "classifier" the shipped kind classifier (g2p-kinds.onnx and its card,
//              docs/kind-classifier.md; calibrated confidences), or an ONNX
//              image classifier the user supplies (settings model, labels:
//              its classes as WordNet ids or words, mapped to kinds through
//              WordNet; size, normalization, channels, min_probability);
//              `auto` takes its settings;
//   "vlm"      a vision-language model asked to name the object (docs/vlm.md);
//   "none"     always unknown (the behaviour before identification).
G2P_API Registry<Identifier>& identifier_registry();
// Creates a backend and applies its settings: identifier_registry().make().
inline Result<std::unique_ptr<Identifier>> make_identifier(const std::string& name,
                                                           const BackendSettings& settings = {}) {
  return identifier_registry().make(name, settings);
}
// The `vlm` identifier with a client of the caller's.
G2P_API std::unique_ptr<Identifier> make_vlm_identifier(std::shared_ptr<const VlmClient> client);

// Convenience: the "auto" identifier on `input`.
G2P_API Result<Identification> identify(const IdentifyInput& input);

// The user's words as a kind: the best match, or kNotFound naming the
// nearest kinds ("--object 'exersize bike' names no kind of the object
// table; nearest: exercise bike, bicycle, ..."). `flag` names the option.
G2P_API Result<std::string> kind_from_text(const ObjectTable& table, const std::string& text,
                                           const std::string& flag = "--object");

// ---- What a kind tells the rest of the run --------------------------------------

// When the pipeline gives a normalised mesh its kind's size.
enum class SizePolicy {
  kKind,  // a mesh that looks normalised, with no size given and a confident kind, gets the kind's typical
          // longest side (the default)
  kFile,  // always keep the file's size
};
G2P_API const char* to_string(SizePolicy policy);  // "kind", "file"
// A size beyond this factor of a kind's usual longest sides, either way, is
// not the kind's: with SizePolicy::kKind and no size given the run takes the
// kind's typical size instead (a 1.9 m camera), and the kind's mass posterior
// does not judge an object given such a size (a toy train called a train).
inline constexpr double kKindSizeTolerance = 1.25;
G2P_API Result<SizePolicy> parse_size_policy(const std::string& text);  // the flag's words

// The properties stage for an object of a known kind: estimate_properties
// with the kind's structure and hidden mass, each said in the report's notes.
//  - A kind that is a hollow body ("hollow": a car, a refrigerator, a box)
//    makes its body, the part with the largest closed volume, hollow with its
//    class's wall where the estimator made it solid (not where a person set
//    it). A shell with contents (a sofa, a filled pot) keeps the estimator's
//    structure: a solid bulk stands for what fills it.
//  - The kind's hidden mass (a refrigerator's compressor, 15 % of its mass)
//    is added to the visible mass m as m F / (1 - F), F the kind's hidden
//    fractions together, as contents of the body's cavity: settled at the
//    bottom (30 % of the cavity) for "bottom", through all of it otherwise,
//    at the density that gives that mass (at most 20,000 kg/m^3; a cavity too
//    small for it keeps what fits, and the note says how much was left out).
//    The centre of mass and the inertia move with it, in every export.
// A body weighed as solid counts its inside already, and nothing is added
// ("hidden mass not added: ..."); with no closed body at all the hidden mass
// is left out ("hidden mass left out: ...", a warning in the pipeline).
// Other kinds: estimate_properties as it is.
G2P_API Result<PropertiesReport> estimate_properties_of_kind(const Mesh& object, const std::vector<Part>& parts,
                                                             const Completion& completion, const MaterialTable& table,
                                                             const PropertyEstimator& estimator, const ObjectKind& kind,
                                                             const std::vector<View>* views = nullptr,
                                                             const StageProgress& progress = {});

// The kind's materials by role as evidence for the image's classes (issue
// #48): a weight per class of `table`, 1 for each class the kind lists
// (ObjectKind::materials) and `other_weight` (in (0, 1]) for every other.
// The pipeline multiplies the probabilities of the classes decided from the
// image alone (the network's pixels, the region classifier's regions) by
// these weights and renormalises (apply_class_prior, segment.h): the kind
// shifts a close call, the image still decides. Empty (no prior) when
// other_weight >= 1 or the kind names no class of `table`. `listed` (when not
// null) receives the listed classes' names, for the report.
G2P_API std::vector<float> kind_class_prior(const ObjectKind& kind, const MaterialTable& table, double other_weight,
                                            std::vector<std::string>* listed = nullptr);

// The identification as JSON (report.json's and run.json's "identification"):
// {"kind" ("unknown" when not known), "confidence", "source", "evidence",
//  "candidates": [{"kind", "confidence", "source", "evidence"}, ...] (at most
//  5), "notes", "warnings", "group", "structure", "typical_longest_side_m",
//  "mass_range_kg": [lo, hi] | null, "size_assumed_m": metres | null}.
// `size_assumed_m` > 0: the longest side the run gave the mesh.
G2P_API std::string identification_json(const Identification& id, const ObjectTable& table,
                                        double size_assumed_m = 0.0);

// How an image classifier sees an object: the views of the `classifier`
// identifier, and the renders the shipped kind classifier was trained on
// (tools/training/make_kind_dataset.cpp), so that both see alike.
struct ClassifierViewOptions {
  int size = 224;                   // pixels: the square side the network takes
  int count = 8;                    // views around the object (a turntable)
  double elevation_deg = 15.0;      // degrees above the object's middle: eye level, as photographs are taken
  int background = 128;             // grey (0-255) wherever the object is not
  std::vector<CameraLight> lights;  // the views' lights; empty = studio_lights()
};

// The classifier's inputs: `count` turntable views rendered at twice `size`,
// each cropped by classifier_crop(). Views that do not show the object are
// left out (the result may be empty).
G2P_API Result<std::vector<ImageU8>> classifier_views(const Renderer& renderer, const Mesh& mesh,
                                                      const ClassifierViewOptions& options = {});

// One view as a classifier takes it: a square about the object's pixels (its
// face IDs) with a margin of 8 % a side, grey `background` wherever the object
// is not, scaled to size x size RGB by area averaging. An empty image when the
// view does not show the object; the whole view when it has no face IDs.
G2P_API ImageU8 classifier_crop(const View& view, int size, int background);

// Shape cues (docs/kind-classifier.md): numbers that say how an object is
// shaped whatever its size, position and turn about the vertical (+Z), for
// the kind classifier to weigh beside its views. In the frame of the
// object's horizontal principal axes (long, short) and its height:
//   height_over_long, short_over_long   log of the extents' ratios
//   mirror_long, mirror_short           how alike the surface is to its
//                                       mirror image across the middle, along
//                                       each horizontal axis (IoU of a 24^3
//                                       surface grid with its mirror, 0-1)
//   surface_fill                        share of that grid's cells the surface
//                                       meets
//   area_height                         height of the surface's centre of area
//                                       over the object's height (0-1)
//   area_bottom, area_top               share of the surface area in the lowest
//                                       and highest quarter of the height
//   footprint_low, _middle, _high       share of the horizontal grid that the
//                                       lowest, middle and highest third of
//                                       the height covers, seen from above
//   area_level, area_upright            share of the area facing within 25
//                                       degrees of vertical (|n_z| > 0.9:
//                                       seats, tops, shelves) and within 17
//                                       degrees of horizontal (|n_z| < 0.3: sides)
// Empty when the mesh has no area or no extent along an axis.
G2P_API const std::vector<std::string>& shape_cue_names();
G2P_API std::vector<double> shape_cues(const Mesh& mesh);

// The table's kinds (`g2p identify --list --json`): [{"name", "group", "coco",
// "typical_longest_side_m", "mass_kg": [lo, hi], "structure"}, ...], indented.
G2P_API std::string object_kinds_json(const ObjectTable& table);

}  // namespace g2p
