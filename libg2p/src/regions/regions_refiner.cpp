// The `regions` refiner: one decision per region by the region classifier
// (regions.h). With scope=image (the default) it decides only the regions
// whose faces the segmenter labelled from the image alone
// (RefineInput::image_decided: the network's faces); names and authored
// values are right where they speak, and the classifier, trained on the
// network's votes, would overrule them. Every other face takes the `smooth`
// refiner's label (rest=smooth, the default) or keeps its voted label
// (rest=keep). A decided region's faces take the classifier's class unless it
// is less sure than `min_probability`, in which case the region keeps its
// `rest` labels. When the classifier cannot run (no card installed, a card
// that cannot be read, no views with base colour) the result is `smooth`'s,
// and the last note says why; a model with no image-decided face never needs
// it. A `card` setting that names no file is refused when configured.
//
// Settings: card (a classifier card; default the shipped g2p-regions.json),
// scope (image | all, default image), rest (smooth | keep, default smooth),
// crease (degrees, default 40), colour (linear RGB step, default 0.1),
// min_area (area share, default 0.002), min_probability (default 0).
// RefineInput::class_prior (the object's kind's materials), when given,
// weighs each decided region's probabilities before its class is chosen.
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
  SettingsSpec settings() override {
    return SettingsSpec("regions")
        .file("card", card_, "the region classifier (a g2p-regions.json); \"\" finds the shipped one")
        .choice("scope", image_only_, {{"image", true}, {"all", false}},
                "decide only the regions the image decided (image) or all")
        .choice("rest", smooth_rest_, {{"smooth", true}, {"keep", false}},
                "the faces it does not decide are smoothed (smooth) or kept")
        .number("crease", options_.crease_deg, Range::closed(0, 180), "degrees",
                "neighbours meeting at a sharper dihedral angle are cut apart")
        .number("colour", options_.colour_step, Range::at_least(0), "",
                "...and neighbours whose colours differ by more (linear RGB, Euclidean)")
        .number("min_area", options_.min_area_fraction, Range::up_to_below(0, 1), "",
                "smaller regions (share of the area) join a neighbour")
        .number("min_probability", min_probability_, Range::closed(0, 1), "",
                "a region is decided only when its best class is at least this probable");
  }

  Result<RefineResult> refine(const RefineInput& in) const override {
    if (in.mesh == nullptr || in.graph == nullptr || in.votes == nullptr || in.labels == nullptr || in.table == nullptr)
      return Status::InvalidArgument("regions: needs the mesh, face graph, votes, labels and material table");
    const std::size_t faces = static_cast<std::size_t>(in.mesh->num_faces());
    if (in.labels->label.size() != faces)
      return Status::InvalidArgument("regions: mesh and labels disagree on the number of faces");

    // The labels of the faces the classifier does not decide.
    RefineResult rest;
    if (smooth_rest_) {
      Result<RefineResult> smoothed = make_smooth_refiner()->refine(in);
      if (!smoothed.ok()) return smoothed.status();
      rest = std::move(*smoothed);
    } else {
      rest.labels = in.labels->label;
    }

    // Which faces the classifier may decide.
    const bool known = in.image_decided != nullptr && in.image_decided->size() == faces;
    const bool everywhere = !image_only_ || !known;  // every region is the classifier's
    std::vector<std::uint8_t> eligible(faces, 1);
    if (!everywhere) eligible = *in.image_decided;
    if (image_only_ && in.image_decided != nullptr && !in.image_decided->empty() && !known)
      rest.notes.push_back("regions: the segmenter's image-decided faces do not match the mesh; every face counts");
    if (std::none_of(eligible.begin(), eligible.end(), [](std::uint8_t e) { return e != 0; })) {
      rest.notes.push_back(std::string("regions: the segmenter labelled no face from the image alone; ") +
                           (smooth_rest_ ? "the smooth refiner's labels stand" : "the voted labels stand"));
      return rest;
    }

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
    if (!why.empty()) return fall_back(in, std::move(rest), why);

    const FaceColours colours = face_colours(*in.mesh, *in.views);
    if (std::all_of(colours.pixels.begin(), colours.pixels.end(), [](float p) { return p == 0.f; }))
      return fall_back(in, std::move(rest), "no view shows any face");
    Result<Regions> regions = find_regions(*in.mesh, *in.graph, colours, options_);
    if (!regions.ok()) return regions.status();
    Result<std::vector<float>> features = region_features(*in.mesh, *regions, *in.votes, colours, *in.table);
    if (!features.ok()) return features.status();
    const int rows = static_cast<int>(regions->regions.size());
    Result<std::vector<float>> probabilities = (*classifier)->predict(*features, rows);
    if (!probabilities.ok()) return fall_back(in, std::move(rest), probabilities.status().message());

    // The reason for each face the classifier changes; the others keep
    // `rest`'s label and reason.
    std::vector<std::string> reasons;
    std::vector<int> reason_of(faces, -1);
    std::vector<int> labels = rest.labels;
    const int k = (*classifier)->num_classes();
    const bool prior = in.class_prior != nullptr && static_cast<int>(in.class_prior->size()) == k;
    int decided = 0, unsure = 0, outside = 0;
    for (int r = 0; r < rows; ++r) {
      const Region& region = regions->regions[static_cast<std::size_t>(r)];
      if (!everywhere) {  // most of the region's area (of its faces, if it has none) is the image's
        double image_area = 0, area = 0;
        std::size_t image_faces = 0;
        for (const int f : region.faces) {
          const double a = face_area(*in.mesh, f);
          area += a;
          if (eligible[static_cast<std::size_t>(f)] == 0) continue;
          image_area += a;
          ++image_faces;
        }
        if (area > 0 ? !(image_area > 0.5 * area) : 2 * image_faces <= region.faces.size()) {
          ++outside;
          continue;
        }
      }
      float* p = probabilities->data() + static_cast<std::size_t>(r) * k;
      if (prior) {  // the kind's materials weigh the classifier's votes
        double total = 0;
        for (int c = 0; c < k; ++c) total += p[c] * (*in.class_prior)[static_cast<std::size_t>(c)];
        for (int c = 0; c < k && total > 0; ++c)
          p[c] = static_cast<float>(p[c] * (*in.class_prior)[static_cast<std::size_t>(c)] / total);
      }
      int best = 0;
      for (int c = 1; c < k; ++c)
        if (p[c] > p[best]) best = c;
      if (p[best] <= 0.f || p[best] < min_probability_) {
        ++unsure;
        continue;
      }
      ++decided;
      char reason[160];
      std::snprintf(reason, sizeof(reason), "region %d (%zu faces): the region classifier says %s (%.0f %%)", r,
                    region.faces.size(), (*in.table)[best].name.c_str(), 100.0 * p[best]);
      reasons.emplace_back(reason);
      for (const int f : region.faces) {
        labels[static_cast<std::size_t>(f)] = best;
        reason_of[static_cast<std::size_t>(f)] = static_cast<int>(reasons.size()) - 1;
      }
    }

    RefineResult result;
    result.labels = std::move(labels);
    std::vector<const LabelChange*> rest_change(faces, nullptr);
    for (const LabelChange& c : rest.changes)
      if (c.face >= 0 && static_cast<std::size_t>(c.face) < faces) rest_change[static_cast<std::size_t>(c.face)] = &c;
    for (std::size_t f = 0; f < faces; ++f) {
      const int from = in.labels->label[f], to = result.labels[f];
      if (from == to) continue;
      const int why_index = reason_of[f];
      result.changes.push_back({static_cast<int>(f), from, to,
                                why_index >= 0              ? reasons[static_cast<std::size_t>(why_index)]
                                : rest_change[f] != nullptr ? rest_change[f]->reason
                                                            : std::string("smooth")});
    }
    result.notes = std::move(rest.notes);
    result.notes.push_back("regions: " + std::to_string(rows) + " regions, " + std::to_string(decided) +
                           " decided by the classifier (" + card + "), " + std::to_string(unsure) + " too unsure and " +
                           std::to_string(outside) + " not labelled from the image kept " +
                           (smooth_rest_ ? "the smooth refiner's labels" : "their voted labels") + "; " +
                           std::to_string(result.changes.size()) + " faces changed");
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

  // `smooth` in its place (its labels already in `rest` with rest=smooth),
  // with the reason as the last note; the stage is marked degraded.
  Result<RefineResult> fall_back(const RefineInput& in, RefineResult rest, const std::string& why) const {
    if (!smooth_rest_) {
      Result<RefineResult> smoothed = make_smooth_refiner()->refine(in);
      if (!smoothed.ok()) return smoothed;
      smoothed->notes.insert(smoothed->notes.begin(), rest.notes.begin(), rest.notes.end());
      rest = std::move(*smoothed);
    }
    rest.notes.push_back("regions: " + why + "; the smooth refiner ran instead");  // last: the pipeline reports it
    rest.fell_back = true;
    return rest;
  }

  std::string card_;
  RegionOptions options_;
  mutable std::mutex mutex_;
  mutable std::shared_ptr<const RegionClassifier> cached_;
  mutable std::string cached_key_;
  double min_probability_ = 0.0;
  bool image_only_ = true;   // scope=image
  bool smooth_rest_ = true;  // rest=smooth
};

}  // namespace

std::unique_ptr<Refiner> make_regions_refiner() { return std::make_unique<RegionsRefiner>(); }

}  // namespace g2p
