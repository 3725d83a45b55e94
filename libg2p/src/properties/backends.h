// Private: the built-in property estimators and the rule they share.
#pragma once

#include <memory>
#include <string>

#include "g2p/properties.h"
#include "g2p/settings.h"

namespace g2p {

std::unique_ptr<PropertyEstimator> make_table_estimator();
std::unique_ptr<PropertyEstimator> make_vlm_estimator();

namespace detail {

// The table rule's knobs (settings of the table and vlm backends).
struct TableRule {
  int rays = 2000;                     // rays per part for measure_walls (0 = class defaults only)
  double dense_kg_m3 = 2000.0;         // classes at least this dense...
  double max_dense_solid_m3 = 0.0005;  // ...are hollow above this closed volume (0.5 litre)
};

// The rule's settings (rays, dense_kg_m3, max_dense_solid_m3), bound to `rule`.
SettingsSpec& bind_table_rule(SettingsSpec& spec, TableRule& rule);

// The table backend's answer for one part (also the vlm backend's fallback):
// the class's values, structure and thickness decided with measure_walls.
Result<PartProperties> table_properties(const PropertyInput& input, const TableRule& rule);

// Checks a structure/thickness choice against the part's geometry: a hollow
// part whose two walls would fill it, or whose shell would outweigh its
// solid volume, is solid. Notes why.
void apply_geometry_guards(PartProperties& p, const CompletedPart& completed);

}  // namespace detail
}  // namespace g2p
