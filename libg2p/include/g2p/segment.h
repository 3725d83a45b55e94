// segment: stage 2 of Gen2Physics. Every rendered pixel gets one of the
// vocabulary's material classes (the paper: a fine-tuned ViT, whose weights
// are not public). libg2p ships a default that reads per-part materials and
// runs its trained network where one material covers the whole object
// (`hybrid`), a weight-free backend (`pbr`), runs any ONNX segmentation model
// (`onnx`) and reads ground truth (`oracle`); researchers register their own
// through segmenter_registry().
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "g2p/image.h"
#include "g2p/materials.h"
#include "g2p/model.h"
#include "g2p/registry.h"
#include "g2p/render.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// Per-pixel material classes of one view.
struct LabelMap {
  ImageI32 labels;       // class index per pixel; kUnknownLabel for background and unknown
  ImageF probabilities;  // one channel per class, summing to 1 on labelled pixels, 0 elsewhere;
                         // empty when the backend gives no probabilities
};

// The segment stage's interface.
class G2P_API Segmenter {
 public:
  virtual ~Segmenter();
  // This backend's settings bound to this instance (settings.h): info()
  // lists them with their values, apply() sets them. Default: none.
  virtual SettingsSpec settings();
  // Applies settings, all or none: a bad key or value leaves the backend as it
  // was. Default: settings().apply(); a backend overrides it only to act on
  // the new values (load a network, make a client).
  virtual Status configure(const BackendSettings& settings);
  // Prepares for the views of one model: the vocabulary to predict, and the
  // model itself (source materials, names) for backends that use it. Both must
  // outlive the segmenter's use of them.
  virtual Status set_model(const Model& model, const MaterialTable& table) = 0;
  // Labels one rendered view of that model: its RGB and, when present, its
  // face IDs and material buffers. Reuses `out`'s memory.
  virtual Status segment_into(const View& view, LabelMap& out) const = 0;
  // What degraded since configure (a fallback taken, and why), for the caller
  // to show; `hybrid` without its network labels as `pbr` and says so here.
  // The pipeline adds them to PipelineResult::warnings. Default: none.
  virtual std::vector<std::string> warnings() const;
  // Per face of the last set_model's mesh: 1 where the labels come from the
  // image (a network reading pixels, with at most a prior from authored PBR),
  // 0 where other evidence decided them (names, authored or default values).
  // Empty when the backend does not say (the default). The `regions` refiner
  // decides only the regions the image decided (refine.h).
  virtual std::vector<std::uint8_t> image_decided_faces() const;

  // Convenience: a new LabelMap.
  Result<LabelMap> segment(const View& view) const;
};

// Backends by name: "hybrid" (the default), "pbr", "onnx", "oracle",
// "learned" (a network where names say nothing, names where they do;
// docs/training.md), "auto".
G2P_API Registry<Segmenter>& segmenter_registry();

// Creates a backend and applies its settings: segmenter_registry().make().
inline Result<std::unique_ptr<Segmenter>> make_segmenter(const std::string& name,
                                                         const BackendSettings& settings = {}) {
  return segmenter_registry().make(name, settings);
}

// ---- A prior over classes ----------------------------------------------------

// Weighs the pixels of `map` whose faces were decided from the image
// (`image_decided`, per face of the view's mesh: Segmenter::image_decided_faces)
// by a prior over classes (`weight`, one per class, for example the object's
// kind's materials: kind_class_prior in identify.h): each such pixel's
// probabilities are multiplied by the weights and renormalised, and its label
// becomes the most probable class. Other pixels, and a map without
// probabilities (a backend that gives labels only), are left as they are; so
// is everything when `weight` is empty. Returns how many labels changed.
// Fails when `weight` does not have one entry per channel of the map's
// probabilities or holds a weight that is not positive and finite.
G2P_API Result<std::size_t> apply_class_prior(const std::vector<float>& weight,
                                              const std::vector<std::uint8_t>& image_decided, const View& view,
                                              LabelMap& map);

// ---- Ground truth -----------------------------------------------------------

// Class label of every source material of `model` from a labels.json-style
// file (../shared/assets/labels.json): {"models": {KEY: {"labels": {"0":
// "Wood", ...}}}} or a bare {"labels": {...}}. "ignore" (void) and materials
// without an entry map to kUnknownLabel; a class name not in `table` is an error.
G2P_API Result<std::vector<int>> material_labels_from_json(const std::string& json_text, const std::string& key,
                                                           const MaterialTable& table, int num_materials);

// How strongly a name (of a material, texture file or mesh) says what the
// surface is made of, per class of `table`: 0 (not at all) to 1 (a material
// word such as "oak", "Stahl", "velours"). The multilingual lexicon of the
// `pbr` backend (docs/segment.md); also the labelling rule of the training
// data (docs/training.md).
G2P_API std::vector<float> material_name_evidence(std::string_view name, const MaterialTable& table);

// Whether a name says nothing: every word of it is one that exporters,
// modelling tools and image-to-3D pipelines give when nobody named anything
// ("Material.001", "Plane.003", "pCubeShape1", "mesh_3", "geometry_0"), or it
// is empty or all digits. A curated asset's own words ("potty", "Wood_oak")
// are not. The `hybrid` segmenter and the `names` identifier skip such names.
G2P_API bool is_placeholder_name(std::string_view name);

// ---- Output -----------------------------------------------------------------

// Labels as colours of the table (background and unknown in `background`).
G2P_API ImageU8 colorize_labels(const ImageI32& labels, const MaterialTable& table,
                                const std::array<std::uint8_t, 3>& background = {0, 0, 0});

// A legend strip: one swatch and name per class.
G2P_API ImageU8 label_legend(const MaterialTable& table, int width = 220);

// Writes per view: view_XX_labels.png (colour-coded, with the legend beside
// it), view_XX_labels_index.png (8-bit class index, 255 = unknown) and
// view_XX_probs.npy (float32, height x width x classes) when there are
// probabilities; plus legend.png, contact_sheet.png (every view's colours
// and the legend) and classes.json (names and colours).
G2P_API Status write_label_maps(const std::string& dir, const std::vector<LabelMap>& maps, const MaterialTable& table);

}  // namespace g2p
