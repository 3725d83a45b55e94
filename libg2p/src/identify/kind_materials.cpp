// kind_class_prior: the object's kind as a prior over material classes.
#include <algorithm>

#include "g2p/identify.h"

namespace g2p {

std::vector<float> kind_class_prior(const ObjectKind& kind, const MaterialTable& table, double other_weight,
                                    std::vector<std::string>* listed) {
  if (listed != nullptr) listed->clear();
  if (!(other_weight > 0.0 && other_weight < 1.0) || table.size() == 0) return {};
  std::vector<float> weight(static_cast<std::size_t>(table.size()), static_cast<float>(other_weight));
  bool any = false;
  for (const KindMaterial& m : kind.materials) {
    const int c = table.find(m.material_class);
    if (c < 0 || weight[static_cast<std::size_t>(c)] == 1.0f) continue;
    weight[static_cast<std::size_t>(c)] = 1.0f;
    any = true;
    if (listed != nullptr) listed->push_back(table[c].name);
  }
  if (!any) return {};
  return weight;
}

}  // namespace g2p
