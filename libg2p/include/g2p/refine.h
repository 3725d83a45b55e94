// refine: stage 4 of Gen2Physics, contextual correction of face labels that
// are consistent across views but wrong. The paper asks a vision-language
// model; libg2p's offline default (`smooth`) minimises a labelling energy on
// the welded face graph. Backends are swappable through refiner_registry().
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "g2p/materials.h"
#include "g2p/mesh.h"
#include "g2p/project.h"
#include "g2p/registry.h"
#include "g2p/render.h"
#include "g2p/status.h"
#include "g2p/visibility.h"
#include "g2p/vlm.h"

namespace g2p {

// What a refiner may look at: the mesh and its face graph, the votes and the
// labels the project stage produced, and the rendered views (for backends that
// show them to a model). All must outlive the call.
struct RefineInput {
  const Mesh* mesh = nullptr;
  const FaceGraph* graph = nullptr;
  const FaceVotes* votes = nullptr;
  const FaceLabels* labels = nullptr;
  const std::vector<View>* views = nullptr;  // may be null for backends that do not need them
  const MaterialTable* table = nullptr;
  // Per face, 1 where the segmenter's labels came from the image alone
  // (Segmenter::image_decided_faces); null or empty: the refiner may not tell
  // image evidence from names, and treats every face alike.
  const std::vector<std::uint8_t>* image_decided = nullptr;
  // A weight per class for the classes decided from the image (the object's
  // kind's materials: kind_class_prior in identify.h); null or empty: none.
  // The `regions` refiner multiplies its regions' probabilities by it.
  const std::vector<float>* class_prior = nullptr;
};

// One face whose label the refiner changed, and why.
struct LabelChange {
  int face = -1;
  int from = kUnknownLabel;
  int to = kUnknownLabel;
  std::string reason;
};

struct RefineResult {
  std::vector<int> labels;           // per face
  std::vector<LabelChange> changes;  // every face whose label differs from the input
  std::vector<std::string> notes;    // what the refiner did or could not do, for the report
  // The backend could not do its work (a model server down, an unusable
  // answer, a classifier not installed) and returned the input labels, or
  // those of the backend it fell back to; `notes` says why. The pipeline
  // reports this as a degraded stage.
  bool fell_back = false;
};

class G2P_API Refiner {
 public:
  virtual ~Refiner();
  // This backend's settings bound to this instance (settings.h): info()
  // lists them with their values, apply() sets them. Default: none.
  virtual SettingsSpec settings();
  // Applies settings, all or none: a bad key or value leaves the backend as it
  // was. Default: settings().apply(); a backend overrides it only to act on
  // the new values (load a network, make a client).
  virtual Status configure(const BackendSettings& settings);
  virtual Result<RefineResult> refine(const RefineInput& input) const = 0;
};

// Backends by name; libg2p registers "smooth" (the offline default), "vlm"
// (a vision-language model over an OpenAI-compatible API, docs/vlm.md),
// "regions" (the region classifier of regions.h) and "none" (labels
// unchanged, for ablations).
G2P_API Registry<Refiner>& refiner_registry();
// Creates a backend and applies its settings: refiner_registry().make().
inline Result<std::unique_ptr<Refiner>> make_refiner(const std::string& name, const BackendSettings& settings = {}) {
  return refiner_registry().make(name, settings);
}

// Puts a refiner's per-face labels into a projection: the parts are
// partitioned again (small fragments merge unless their votes were confident)
// and each face's confidence becomes its votes' share for its new label.
G2P_API Status apply_refinement(const Mesh& mesh, const std::vector<int>& labels, const PartitionOptions& options,
                                Projection& projection);

// The `vlm` refiner with a client of the caller's (any VlmClient subclass).
G2P_API std::unique_ptr<Refiner> make_vlm_refiner(std::shared_ptr<const VlmClient> client);

}  // namespace g2p
