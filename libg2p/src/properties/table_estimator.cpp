// The PropertyEstimator base class, the registry and the `table` backend.
//
// The `table` rule for solid or hollow, from measure_walls and the class
// (numbered as in docs/properties.md, "The table backend"):
// 1. The class's values (source: table).
// 2. Modelled walls: if at least half of the rays cast into the part's closed
//    volume meet an inner surface of the object before leaving it (the model
//    has an inside: a bottle's inner wall), the part is hollow, double-walled,
//    and its wall thickness is the median distance to that surface (source:
//    geometry). Only an inner surface no farther in than the class's thickest
//    solid piece counts (max_solid_thickness_m, 0 = no limit): a steel "wall"
//    10 cm thick is the gap to another part of the object. A counted wall
//    thicker than the class's thickest single wall (max_wall_thickness_m,
//    0 = no limit) is a closed section instead: hollow, single-walled, every
//    face a wall of the class's thickness (structure source: geometry). Sheet
//    metal ends at about 6 mm; a 30 mm "steel panel" is a box of sheet.
// 3. Dense bulk: the parts of a dense class (>= 2000 kg/m^3: metal, glass,
//    ceramic, stone) solid by default are hollow with the class's wall
//    thickness when together they enclose more than half a litre of the
//    object (source: geometry): a solid steel water bottle would weigh 14 kg;
//    things that big are shells. (A hammer's steel head, 0.17 litres, stays
//    solid.)
// 4. A part of a class solid by default that is thicker (median local
//    thickness) than the class's thickest solid piece is a single-walled shell
//    of the class's wall thickness (source: geometry): a wardrobe modelled as
//    a closed box is panels around air, a tyre is rubber around air.
// 5. Otherwise the class's default structure and thickness (source: table).
// 6. Guards (source: geometry): a hollow part thinner than two walls (median
//    local thickness <= 2 t), or whose shell A t would exceed its volume, is
//    solid: its walls fill it. A part that the guards filled but that is
//    thicker than its class's thickest solid piece is still rule 4's shell.
#include <cmath>
#include <sstream>

#include "core/settings.h"
#include "properties/backends.h"

namespace g2p {

PropertyEstimator::~PropertyEstimator() = default;

SettingsSpec PropertyEstimator::settings() { return SettingsSpec("this estimator"); }

Status PropertyEstimator::configure(const BackendSettings& settings) { return this->settings().apply(settings); }

const char* to_string(ValueSource source) {
  switch (source) {
    case ValueSource::kTable: return "table";
    case ValueSource::kGeometry: return "geometry";
    case ValueSource::kVlm: return "vlm";
    case ValueSource::kUser: return "user";
    case ValueSource::kKind: return "kind";
  }
  return "unknown";
}

namespace detail {

namespace {
std::string mm(double m) {
  std::ostringstream s;
  s.precision(3);
  s << m * 1000 << " mm";
  return s.str();
}
// The closed volume of all the object's parts of this part's class (just
// this part's without the object context).
double class_volume_m3(const PropertyInput& in) {
  if (in.all_parts == nullptr || in.all_completed == nullptr || in.all_parts->size() != in.all_completed->parts.size())
    return in.completed->checks.volume_m3;
  double v = 0.0;
  for (std::size_t i = 0; i < in.all_parts->size(); ++i)
    if ((*in.all_parts)[i].label == in.part->label) v += in.all_completed->parts[i].checks.volume_m3;
  return v;
}

}  // namespace

SettingsSpec& bind_table_rule(SettingsSpec& spec, TableRule& rule) {
  return spec
      .integer("rays", rule.rays, 0, 1000000, "", "rays per part measuring its walls (0: the classes' defaults only)")
      .number("dense_kg_m3", rule.dense_kg_m3, Range::above(0), "kg/m^3", "classes at least this dense...")
      .number("max_dense_solid_m3", rule.max_dense_solid_m3, Range::at_least(0), "m^3",
              "...are hollow above this closed volume");
}

void apply_geometry_guards(PartProperties& p, const CompletedPart& completed) {
  if (p.structure != Structure::kHollow) return;
  const double t = p.wall_thickness_m;
  if (p.walls.rays > 0 && p.walls.thickness_m <= 2 * t) {
    p.structure = Structure::kSolid;
    p.double_walled = false;
    p.structure_source = ValueSource::kGeometry;
    p.notes.push_back("solid: the part is " + mm(p.walls.thickness_m) + " thick, no more than two " + mm(t) + " walls");
  } else if (completed.checks.area_m2 * t >= completed.checks.volume_m3) {
    p.structure = Structure::kSolid;
    p.double_walled = false;
    p.structure_source = ValueSource::kGeometry;
    p.notes.push_back("solid: a " + mm(t) + " shell over its area would exceed its volume");
  }
}

Result<PartProperties> table_properties(const PropertyInput& in, const TableRule& rule) {
  if (in.object == nullptr || in.part == nullptr || in.completed == nullptr || in.table == nullptr)
    return Status::InvalidArgument("properties: needs the object, the part, its completed volume and the table");
  const MaterialTable& table = *in.table;
  const int label = in.part->label;
  if (!table.valid_label(label))
    return Status::InvalidArgument("properties: part with label " + std::to_string(label) +
                                   " has no class in the table '" + table.name() + "'");
  const MaterialClass& c = table[label];
  PartProperties p;
  p.label = label;
  p.density_kg_m3 = c.density_kg_m3;
  p.density_min_kg_m3 = c.density_min_kg_m3;
  p.density_max_kg_m3 = c.density_max_kg_m3;
  p.structure = c.structure;
  p.wall_thickness_m = c.wall_thickness_m;
  p.friction_static = c.friction_static;
  p.friction_dynamic = c.friction_dynamic;
  p.restitution = c.restitution;
  if (in.completed->mesh.num_faces() > 0) {
    const double tolerance = in.all_completed != nullptr ? in.all_completed->grid_spacing_m : 0.0;
    Result<WallMeasurement> w =
        in.object_rays != nullptr
            ? measure_walls(*in.object_rays, *in.object, *in.part, in.completed->mesh, rule.rays, tolerance)
            : measure_walls(*in.object, *in.part, in.completed->mesh, rule.rays, tolerance);
    if (!w.ok()) return w.status();
    p.walls = *w;
  }
  const double max_solid = c.max_solid_thickness_m;  // 0 = no limit
  const bool measured_inside = p.walls.rays > 0 && p.walls.inner_fraction() >= 0.5 && p.walls.inner_wall_m > 0;
  const bool wall_too_thick = measured_inside && max_solid > 0 && p.walls.inner_wall_m > max_solid;
  if (wall_too_thick)
    p.notes.push_back("an inner surface " + mm(p.walls.inner_wall_m) + " in is farther than the thickest solid " +
                      c.name + " (" + mm(max_solid) + "): another part, not this part's wall");
  // A modelled wall thicker than the class's thickest single wall is a closed
  // section (a steel panel 30 mm thick is a box of sheet, not a 30 mm plate).
  const double max_wall = c.max_wall_thickness_m;  // 0 = no limit
  const bool closed_section = measured_inside && !wall_too_thick && max_wall > 0 && p.walls.inner_wall_m > max_wall;
  if (closed_section) {
    p.structure = Structure::kHollow;
    p.double_walled = false;
    p.structure_source = ValueSource::kGeometry;
    p.notes.push_back("hollow: the modelled walls are " + mm(p.walls.inner_wall_m) + " thick, more than the thickest " +
                      c.name + " wall (" + mm(max_wall) + "): a closed section, each face a " + mm(p.wall_thickness_m) +
                      " wall (the class's)");
  } else if (measured_inside && !wall_too_thick) {
    p.structure = Structure::kHollow;
    p.wall_thickness_m = p.walls.inner_wall_m;
    p.double_walled = true;
    p.structure_source = p.thickness_source = ValueSource::kGeometry;
    p.notes.push_back("hollow: " + std::to_string(static_cast<int>(100 * p.walls.inner_fraction())) +
                      "% of rays into the part meet an inner surface, at a median " + mm(p.walls.inner_wall_m));
  } else if (const double class_volume = class_volume_m3(in); c.structure == Structure::kSolid &&
                                                              c.density_kg_m3 >= rule.dense_kg_m3 &&
                                                              class_volume > rule.max_dense_solid_m3) {
    p.structure = Structure::kHollow;
    p.structure_source = ValueSource::kGeometry;
    std::ostringstream note;
    note.precision(3);
    note << "hollow: the object's " << c.name << " parts enclose " << class_volume * 1000
         << " litres, which would weigh " << class_volume * c.density_kg_m3
         << " kg solid; dense parts this large are shells (" << mm(p.wall_thickness_m) << " walls, the class's)";
    p.notes.push_back(note.str());
  } else if (c.structure == Structure::kSolid && max_solid > 0 && p.walls.rays > 0 && p.walls.thickness_m > max_solid) {
    p.structure = Structure::kHollow;
    p.structure_source = ValueSource::kGeometry;
    p.notes.push_back("hollow: the part is " + mm(p.walls.thickness_m) + " thick, more than the thickest solid " +
                      c.name + " (" + mm(max_solid) + "): a shell of " + mm(p.wall_thickness_m) +
                      " walls (the class's)");
  } else {
    p.notes.push_back(std::string(to_string(c.structure)) + ": the class's default" +
                      (wall_too_thick ? "" : " (no modelled inner walls)"));
  }
  apply_geometry_guards(p, *in.completed);
  // Modelled walls that the guards filled (the part no thicker than two of
  // them) give a solid part; one thicker than its class's thickest solid
  // piece is still a shell of the class's wall (rule 3).
  if (p.structure == Structure::kSolid && p.structure_source == ValueSource::kGeometry &&
      c.structure == Structure::kSolid && max_solid > 0 && p.walls.rays > 0 && p.walls.thickness_m > max_solid) {
    p.structure = Structure::kHollow;
    p.wall_thickness_m = c.wall_thickness_m;
    p.thickness_source = ValueSource::kTable;
    p.notes.push_back("hollow: the part is " + mm(p.walls.thickness_m) + " thick, more than the thickest solid " +
                      c.name + " (" + mm(max_solid) + "): a shell of " + mm(p.wall_thickness_m) +
                      " walls (the class's)");
    apply_geometry_guards(p, *in.completed);
  }
  return p;
}

}  // namespace detail

namespace {

class TableEstimator final : public PropertyEstimator {
 public:
  SettingsSpec settings() override {
    SettingsSpec spec("table");
    return detail::bind_table_rule(spec, rule_);
  }
  Result<PartProperties> estimate(const PropertyInput& input) const override {
    return detail::table_properties(input, rule_);
  }

 private:
  detail::TableRule rule_;
};

}  // namespace

std::unique_ptr<PropertyEstimator> make_table_estimator() { return std::make_unique<TableEstimator>(); }

Registry<PropertyEstimator>& estimator_registry() {
  static Registry<PropertyEstimator>* registry = [] {
    auto* r = new Registry<PropertyEstimator>("estimator");  // never destroyed: usable during static destruction
    (void)r->add("table", &make_table_estimator);
    (void)r->add("vlm", [] { return make_vlm_estimator(); });
    return r;
  }();
  return *registry;
}

}  // namespace g2p
