// The `regions` refiner: one decision per region by the region classifier
// (regions.h). Every face of a region takes the class the classifier gives
// the region, unless the classifier is less sure than `min_probability`, in
// which case the region keeps the labels the project stage gave it. When the
// classifier cannot run (no card installed, a card that cannot be read, no
// views with base colour) it falls back to `smooth` and says why in its last
// note. A `card` setting that names no file is refused when configured.
//
// Settings: card (a classifier card; default the shipped g2p-regions.json),
// crease (degrees, default 40), colour (linear RGB step, default 0.1),
// min_area (area share, default 0.002), min_probability (default 0).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>

#include "core/settings.h"
#include "g2p/regions.h"
#include "refine/backends.h"

namespace g2p {
namespace {

class RegionsRefiner final : public Refiner {
 public:
  Status configure(const BackendSettings& settings) override {
    for (const auto& [key, value] : settings) {
      if (key == "card") {
        std::error_code ec;
        if (value.empty() || !std::filesystem::is_regular_file(value, ec))
          return Status::InvalidArgument("regions: card=" + value + " is not a file (a g2p-regions.json)");
        card_ = value;
        continue;
      }
      double v = 0;
      if (!detail::parse_double(value, v))
        return Status::InvalidArgument("regions: " + key + " needs a number, got '" + value + "'");
      if (key == "crease" && v >= 0 && v <= 180)
        options_.crease_deg = v;
      else if (key == "colour" && v >= 0)
        options_.colour_step = v;
      else if (key == "min_area" && v >= 0 && v < 1)
        options_.min_area_fraction = v;
      else if (key == "min_probability" && v >= 0 && v <= 1)
        min_probability_ = v;
      else
        return Status::InvalidArgument("regions: bad setting " + key + "=" + value +
                                       " (known: card, crease in [0, 180], colour >= 0, min_area in [0, 1), "
                                       "min_probability in [0, 1])");
    }
    return Status::Ok();
  }

  Result<RefineResult> refine(const RefineInput& in) const override {
    if (in.mesh == nullptr || in.graph == nullptr || in.votes == nullptr || in.labels == nullptr || in.table == nullptr)
      return Status::InvalidArgument("regions: needs the mesh, face graph, votes, labels and material table");
    if (static_cast<int>(in.labels->label.size()) != in.mesh->num_faces())
      return Status::InvalidArgument("regions: mesh and labels disagree on the number of faces");
    std::string why;
    const std::string card = card_.empty() ? shipped_region_card() : card_;
    Result<std::shared_ptr<const RegionClassifier>> classifier = Status::NotFound("");
    const bool base_colour = in.views != nullptr && std::any_of(in.views->begin(), in.views->end(),
                                                                [](const View& v) { return !v.base_color.empty(); });
    if (card.empty())
      why = "the region classifier g2p-regions.json is not installed";
    else if (in.views == nullptr || in.views->empty())
      why = "no rendered views to read the regions' colours from";
    else if (!base_colour)
      // The classifier learnt base colours; shaded images (all that g2p
      // refine DIR keeps) would give it colours it never saw.
      why = "the views have no base-colour buffer, the colours the classifier was trained on";
    else if (classifier = load(card, *in.table); !classifier.ok())
      why = classifier.status().message();
    if (!why.empty()) return fall_back(in, why);

    const FaceColours colours = face_colours(*in.mesh, *in.views);
    if (std::all_of(colours.pixels.begin(), colours.pixels.end(), [](float p) { return p == 0.f; }))
      return fall_back(in, "no view shows any face");
    Result<Regions> regions = find_regions(*in.mesh, *in.graph, colours, options_);
    if (!regions.ok()) return regions.status();
    Result<std::vector<float>> features = region_features(*in.mesh, *regions, *in.votes, colours, *in.table);
    if (!features.ok()) return features.status();
    const int rows = static_cast<int>(regions->regions.size());
    Result<std::vector<float>> probabilities = (*classifier)->predict(*features, rows);
    if (!probabilities.ok()) return fall_back(in, probabilities.status().message());

    RefineResult result;
    result.labels = in.labels->label;
    const int k = (*classifier)->num_classes();
    int decided = 0, kept = 0;
    for (int r = 0; r < rows; ++r) {
      const float* p = probabilities->data() + static_cast<std::size_t>(r) * k;
      int best = 0;
      for (int c = 1; c < k; ++c)
        if (p[c] > p[best]) best = c;
      if (p[best] <= 0.f || p[best] < min_probability_) {
        ++kept;
        continue;
      }
      ++decided;
      char reason[160];
      std::snprintf(reason, sizeof(reason), "region %d (%zu faces): the region classifier says %s (%.0f %%)", r,
                    regions->regions[static_cast<std::size_t>(r)].faces.size(), (*in.table)[best].name.c_str(),
                    100.0 * p[best]);
      for (const int f : regions->regions[static_cast<std::size_t>(r)].faces) {
        int& label = result.labels[static_cast<std::size_t>(f)];
        if (label == best) continue;
        result.changes.push_back({f, label, best, reason});
        label = best;
      }
    }
    result.notes.push_back("regions: " + std::to_string(rows) + " regions, " + std::to_string(decided) +
                           " decided by the classifier (" + card + "), " + std::to_string(kept) +
                           " kept their voted labels; " + std::to_string(result.changes.size()) + " faces changed");
    return result;
  }

 private:
  // The classifier, read once per card and table (the trees file is 5 MB).
  Result<std::shared_ptr<const RegionClassifier>> load(const std::string& card, const MaterialTable& table) const {
    std::string key = card;
    for (const MaterialClass& c : table.classes()) key += "\n" + c.name;
    std::lock_guard<std::mutex> lock(mutex_);
    if (cached_ != nullptr && key == cached_key_) return cached_;
    Result<RegionClassifier> loaded = RegionClassifier::load(card, table);
    if (!loaded.ok()) return loaded.status();
    cached_ = std::make_shared<const RegionClassifier>(std::move(*loaded));
    cached_key_ = key;
    return cached_;
  }

  // `smooth` in its place, with the reason as the last note; the stage is
  // marked degraded.
  Result<RefineResult> fall_back(const RefineInput& in, const std::string& why) const {
    Result<RefineResult> r = make_smooth_refiner()->refine(in);
    if (!r.ok()) return r;
    r->notes.push_back("regions: " + why + "; the smooth refiner ran instead");  // last: the pipeline reports it
    r->fell_back = true;
    return r;
  }

  std::string card_;
  RegionOptions options_;
  mutable std::mutex mutex_;
  mutable std::shared_ptr<const RegionClassifier> cached_;
  mutable std::string cached_key_;
  double min_probability_ = 0.0;
};

}  // namespace

std::unique_ptr<Refiner> make_regions_refiner() { return std::make_unique<RegionsRefiner>(); }

}  // namespace g2p
