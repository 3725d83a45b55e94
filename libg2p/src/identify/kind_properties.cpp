// estimate_properties_of_kind: the properties stage told what the object is.
// The kind's structure makes its body hollow; its hidden mass (machinery,
// ballast, a flywheel) goes into the body's cavity as contents, so that the
// centre of mass and the inertia carry it. The formulas are in identify.h.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>

#include "g2p/identify.h"
#include "identify/kind_properties.h"
#include "properties/report.h"

namespace g2p {
namespace {

constexpr double kMaxHiddenDensity = 20000.0;  // kg/m^3: above tungsten; a cavity needing more is too small
constexpr double kBottomFill = 0.3;            // the share of the cavity a "bottom" load settles into

std::string format(const char* f, double a, double b = 0.0, double c = 0.0) {
  char text[160];
  std::snprintf(text, sizeof text, f, a, b, c);
  return text;
}

std::string article(const std::string& noun) {
  const bool vowel = !noun.empty() && std::string("aeiou").find(noun.front()) != std::string::npos;
  return (vowel ? "an " : "a ") + noun;
}

// The base estimator's answers, remembered per part (so that the passes
// that place the hidden mass do not measure the walls again), with the
// kind's body made hollow and, once known, the hidden mass as its contents.
class KindEstimator final : public PropertyEstimator {
 public:
  KindEstimator(const PropertyEstimator& base, const ObjectKind& kind, const std::vector<Part>& parts, int body)
      : base_(base), kind_(kind), parts_(parts), body_(body) {}

  void set_contents(double fill, double density) {
    fill_ = fill;
    density_ = density;
  }

  Result<PartProperties> estimate(const PropertyInput& in) const override {
    const int index = in.part != nullptr ? static_cast<int>(in.part - parts_.data()) : -1;
    PartProperties p;
    bool cached = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const auto it = cache_.find(index);
      if (it != cache_.end()) {
        p = it->second;
        cached = true;
      }
    }
    if (!cached) {
      Result<PartProperties> r = base_.estimate(in);
      if (!r.ok()) return r;
      p = std::move(*r);
      // Only a shell around air: a sofa's or a flower pot's solid bulk already stands for what fills them.
      if (index == body_ && kind_.structure == "hollow" && p.structure == Structure::kSolid &&
          p.structure_source != ValueSource::kUser && p.structure_source != ValueSource::kKind &&
          in.completed != nullptr) {  // kKind: the kind's mass posterior chose it already
        double wall =
            in.table != nullptr && in.table->valid_label(p.label) ? (*in.table)[p.label].wall_thickness_m : 0.0;
        if (!(wall > 0)) wall = MaterialClass{}.wall_thickness_m;
        // A shell thicker than the part itself is no shell: it stays solid.
        if (in.completed->checks.area_m2 * wall < in.completed->checks.volume_m3) {
          p.structure = Structure::kHollow;
          p.wall_thickness_m = wall;
          p.double_walled = false;
          p.structure_source = ValueSource::kKind;
          p.notes.push_back("hollow, " + format("%.3g", wall * 1000.0) + " mm walls: " + article(kind_.name) +
                            "'s body is a hollow shell (the object table)");
        }
      }
      std::lock_guard<std::mutex> lock(mutex_);
      cache_[index] = p;
    }
    if (index == body_ && fill_ > 0 && p.structure == Structure::kHollow) {
      p.contents_fill = fill_;
      p.contents_density_kg_m3 = density_;
    }
    return p;
  }

 private:
  const PropertyEstimator& base_;
  const ObjectKind& kind_;
  const std::vector<Part>& parts_;
  int body_;
  double fill_ = 0.0, density_ = 0.0;
  mutable std::mutex mutex_;
  mutable std::map<int, PartProperties> cache_;
};

// The report of part `part`, or null.
const PartReport* part_report(const PropertiesReport& r, int part) {
  for (const PartReport& p : r.parts)
    if (p.part == part) return &p;
  return nullptr;
}

}  // namespace

Result<PropertiesReport> estimate_properties_of_kind(const Mesh& object, const std::vector<Part>& parts,
                                                     const Completion& completion, const MaterialTable& table,
                                                     const PropertyEstimator& estimator, const ObjectKind& kind,
                                                     const std::vector<View>* views, const StageProgress& progress) {
  Result<std::shared_ptr<const SurfaceRays>> object_rays = SurfaceRays::build(object);
  if (!object_rays.ok()) return object_rays.status().with_context("properties");
  return detail::estimate_properties_of_kind(object, parts, completion, table, estimator, kind, views, progress,
                                             **object_rays);
}

Result<PropertiesReport> detail::estimate_properties_of_kind(const Mesh& object, const std::vector<Part>& parts,
                                                             const Completion& completion, const MaterialTable& table,
                                                             const PropertyEstimator& estimator, const ObjectKind& kind,
                                                             const std::vector<View>* views,
                                                             const StageProgress& progress,
                                                             const SurfaceRays& object_rays) {
  // The body: the part with the largest closed volume.
  int body = -1;
  double largest = 0.0;
  for (std::size_t i = 0; i < completion.parts.size() && i < parts.size(); ++i) {
    const CompletedPart& c = completion.parts[i];
    if (c.ok && c.checks.volume_m3 > largest) {
      largest = c.checks.volume_m3;
      body = static_cast<int>(i);
    }
  }
  KindEstimator by_kind(estimator, kind, parts, body);
  Result<PropertiesReport> report =
      detail::estimate_properties(object, parts, completion, table, by_kind, views, progress, object_rays);
  if (!report.ok() || kind.hidden.empty()) return report;

  double fraction = 0.0;
  std::string what;
  bool bottom = true;
  for (const HiddenContent& h : kind.hidden) {
    fraction += h.mass_fraction;
    what += (what.empty() ? "" : ", ") + h.what;
    bottom = bottom && h.where == "bottom";
  }
  fraction = std::min(fraction, 0.9);
  const double visible = report->object.mass_kg;
  const double hidden = visible * fraction / (1.0 - fraction);
  const std::string said =
      what + " (" + format("%.0f", 100.0 * fraction) + " % of " + article(kind.name) + "'s mass, the object table)";
  const PartReport* body_report = part_report(*report, body);
  if (!(hidden > 0)) return report;
  if (body_report == nullptr || !(body_report->mass.mass_kg > 0)) {
    report->notes.push_back("hidden mass left out: " + said + ": no part with a closed volume to hold it");
    return report;
  }
  if (body_report->properties.structure != Structure::kHollow) {  // its inside is weighed already
    report->notes.push_back("hidden mass not added: " + said + ": part " + std::to_string(body) +
                            ", the body, is weighed as solid, inside included");
    return report;
  }
  // The cavity's volume: the contents' mass with the whole cavity at 1000 kg/m^3.
  by_kind.set_contents(1.0, 1000.0);
  Result<PropertiesReport> probe =
      detail::estimate_properties(object, parts, completion, table, by_kind, views, progress, object_rays);
  if (!probe.ok()) return probe.status();
  const PartReport* probed = part_report(*probe, body);
  const double cavity_m3 = probed != nullptr ? probed->contents.mass_kg / 1000.0 : 0.0;
  if (!(cavity_m3 > 0)) {
    report->notes.push_back("hidden mass left out: " + said + ": part " + std::to_string(body) + " has no cavity");
    return report;
  }
  double fill = bottom ? kBottomFill : 1.0;
  double density = hidden / (fill * cavity_m3);
  if (density > kMaxHiddenDensity && fill < 1.0) {  // spread it up before making it denser
    fill = std::min(1.0, hidden / (kMaxHiddenDensity * cavity_m3));
    density = hidden / (fill * cavity_m3);
  }
  density = std::min(density, kMaxHiddenDensity);
  by_kind.set_contents(fill, density);
  Result<PropertiesReport> placed =
      detail::estimate_properties(object, parts, completion, table, by_kind, views, progress, object_rays);
  if (!placed.ok()) return placed.status();
  const PartReport* held_by = part_report(*placed, body);
  const double held = held_by != nullptr ? held_by->contents.mass_kg : 0.0;
  placed->notes = report->notes;
  std::string note = "hidden mass: " + said + ": " + format("%.3g kg", held) + " inside part " + std::to_string(body) +
                     ", " +
                     (fill < 1.0 ? format("the bottom %.0f %% of its cavity", 100.0 * fill) : "through its cavity");
  if (held < 0.99 * hidden)
    note += format("; %.3g kg of %.3g kg, the rest does not fit at 20,000 kg/m^3", held, hidden);
  placed->notes.push_back(note);
  return placed;
}

}  // namespace g2p
