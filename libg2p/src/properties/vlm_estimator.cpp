// The `vlm` estimator: the paper's stage 6 question to a vision-language
// model. For each part it sends the object's renders with the part coloured
// in, the part's class and measured geometry, and asks for the density, solid
// or hollow, and the wall thickness as a JSON object. Values outside physical
// ranges are refused; any failure (no server, bad JSON, refused values)
// falls back to the `table` answer with a note, so the stage never stops here.
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/physical_limits.h"
#include "core/settings.h"
#include "g2p/project.h"
#include "io/image_io.h"
#include "properties/backends.h"

namespace g2p {
namespace {

using nlohmann::json;

constexpr double kMinDensity = detail::kMinSolidDensity_kg_m3;
constexpr double kMaxDensity = detail::kMaxDensity_kg_m3;

class VlmEstimator final : public PropertyEstimator {
 public:
  explicit VlmEstimator(std::shared_ptr<const VlmClient> client = nullptr)
      : client_(std::move(client)), injected_(client_ != nullptr) {}

  SettingsSpec settings() override {
    SettingsSpec spec("vlm");
    detail::bind_openai(spec, options_)
        .integer("max_views", max_views_, 0, 100, "", "views sent, each as render and part mask");
    return detail::bind_table_rule(spec, rule_).check([this] { return connect(); });
  }

  Result<PartProperties> estimate(const PropertyInput& in) const override {
    Result<PartProperties> table = detail::table_properties(in, rule_);
    if (!table.ok()) return table.status();
    PartProperties p = std::move(*table);
    auto fall_back = [&](const std::string& why) {
      p.notes.push_back("vlm: " + why + "; the table's values stand");
      return p;
    };
    if (client_ == nullptr) return fall_back("no model configured (setting model=NAME, url=...)");
    Result<VlmRequest> request = build_request(in, p);
    if (!request.ok()) return fall_back(request.status().message());
    Result<std::string> answer = client_->complete(*request);
    if (!answer.ok()) return fall_back(answer.status().to_string());
    Result<std::string> text = extract_json_object(*answer);
    if (!text.ok()) return fall_back("no JSON object in the answer");
    const json j = json::parse(*text, nullptr, false);
    if (j.is_discarded() || !j.is_object()) return fall_back("the answer's JSON does not parse");
    const double density = j.value("density_kg_m3", -1.0);
    const std::string structure = j.value("structure", "");
    const double thickness = j.value("wall_thickness_m", -1.0);
    if (!(density >= kMinDensity && density <= kMaxDensity))
      return fall_back("density " + std::to_string(density) + " kg/m^3 is outside [10, 23000]");
    if (structure != "solid" && structure != "hollow") return fall_back("structure must be 'solid' or 'hollow'");
    const double local = p.walls.thickness_m > 0 ? p.walls.thickness_m : 1e9;
    if (structure == "hollow" && !(thickness > 0 && thickness <= 0.5 * local))
      return fall_back("wall thickness " + std::to_string(thickness) + " m is not in (0, " +
                       std::to_string(0.5 * local) + "] (half the part's thickness)");
    // The range keeps the class's relative spread around the model's value.
    const MaterialClass& c = (*in.table)[p.label];
    p.density_min_kg_m3 = density * c.density_min_kg_m3 / c.density_kg_m3;
    p.density_max_kg_m3 = density * c.density_max_kg_m3 / c.density_kg_m3;
    p.density_kg_m3 = density;
    p.density_source = ValueSource::kVlm;
    p.structure = structure == "hollow" ? Structure::kHollow : Structure::kSolid;
    p.structure_source = ValueSource::kVlm;
    if (p.structure == Structure::kHollow) {
      if (!(p.thickness_source == ValueSource::kGeometry && p.double_walled)) p.double_walled = false;
      p.wall_thickness_m = thickness;
      p.thickness_source = ValueSource::kVlm;
    }
    p.notes.push_back("vlm: " + j.value("reason", std::string("(no reason given)")));
    detail::apply_geometry_guards(p, *in.completed);
    return p;
  }

 private:
  // A client for the settings as they are; without a model, the table's values.
  Status connect() {
    if (injected_ || options_.model.empty()) return Status::Ok();
    Result<std::unique_ptr<VlmClient>> c = make_openai_client(options_);
    if (!c.ok()) return c.status();
    client_ = std::move(*c);
    return Status::Ok();
  }

  Result<VlmRequest> build_request(const PropertyInput& in, const PartProperties& p) const {
    const Eigen::AlignedBox3d object_box = bounds(*in.object);
    const Eigen::AlignedBox3d part_box = bounds(in.completed->mesh);
    std::ostringstream s;
    s.precision(4);
    s << "An object of size " << object_box.sizes().transpose() << " m has a part made of " << (*in.table)[p.label].name
      << ". The part is " << part_box.sizes().transpose() << " m across; its closed volume is "
      << in.completed->checks.volume_m3 * 1e6 << " cm^3 and its surface " << in.completed->checks.area_m2 * 1e4
      << " cm^2; rays into it cross a median " << p.walls.thickness_m * 1000 << " mm of it.";
    if (!in.views || in.views->empty() || max_views_ == 0)
      s << " No images are attached.";
    else
      s << " The images show the object, then the same view with the part coloured in.";
    s << "\nEstimate the part's real density, whether it is solid or hollow (a shell, like a bottle or a "
         "tube), and if hollow its wall thickness. Answer with one JSON object: {\"density_kg_m3\": number, "
         "\"structure\": \"solid\" or \"hollow\", \"wall_thickness_m\": number (hollow only), \"reason\": short "
         "text}.";
    VlmRequest r;
    r.system = "You are an expert in materials, manufacturing and product design. Answer precisely.";
    r.prompt = s.str();
    if (in.views != nullptr && max_views_ > 0) {
      std::vector<int> mask(static_cast<std::size_t>(in.object->num_faces()), kUnknownLabel);
      for (int f : in.part->faces) mask[static_cast<std::size_t>(f)] = p.label;
      const std::size_t n = in.views->size();
      const std::size_t step = std::max<std::size_t>(1, (n + static_cast<std::size_t>(max_views_) - 1) / max_views_);
      for (std::size_t v = 0; v < n; v += step) {
        const View& view = (*in.views)[v];
        if (view.rgb.empty()) continue;
        Result<std::string> rgb = detail::encode_png(view.rgb);
        Result<std::string> part =
            detail::encode_png(colorize_labels(render_face_labels(view, mask).labels, *in.table));
        if (!rgb.ok() || !part.ok()) return Status::Internal("could not encode the views as PNG");
        r.images.push_back({*rgb, "View " + std::to_string(v) + ":"});
        r.images.push_back({*part, "View " + std::to_string(v) + ", the part coloured in:"});
      }
    }
    return r;
  }

  std::shared_ptr<const VlmClient> client_;
  bool injected_ = false;
  OpenAiClientOptions options_;
  int max_views_ = 4;       // views sent (each as render and part mask)
  detail::TableRule rule_;  // the fallback's
};

}  // namespace

std::unique_ptr<PropertyEstimator> make_vlm_estimator() { return std::make_unique<VlmEstimator>(); }
std::unique_ptr<PropertyEstimator> make_vlm_estimator(std::shared_ptr<const VlmClient> client) {
  return std::make_unique<VlmEstimator>(std::move(client));
}

}  // namespace g2p
