// fit_classes_to_kind: a class covers no more of the object's surface than
// the object's kind allows it (posterior.h).
#include <algorithm>
#include <cstdio>

#include "g2p/posterior.h"

namespace g2p {

namespace {

std::string percent(double share) {
  char text[16];
  std::snprintf(text, sizeof text, "%.0f %%", 100.0 * share);
  return text;
}

}  // namespace

std::vector<double> part_class_probabilities(const FaceVotes& votes, const Part& part, int num_classes) {
  std::vector<double> p(static_cast<std::size_t>(num_classes), 0.0);
  if (votes.num_classes != num_classes || votes.row.empty()) return {};
  double total = 0.0;
  for (int f : part.faces) {
    if (f < 0 || static_cast<std::size_t>(f) >= votes.row.size()) continue;
    const float* v = votes.of(f);
    if (v == nullptr) continue;
    for (int c = 0; c < num_classes; ++c) {
      p[static_cast<std::size_t>(c)] += v[c];
      total += v[c];
    }
  }
  if (!(total > 0.0)) return {};
  for (double& x : p) x /= total;
  return p;
}

std::vector<double> kind_class_shares(const ObjectKind& kind, const MaterialTable& table,
                                      const PosteriorOptions& options) {
  std::vector<double> share(static_cast<std::size_t>(table.size()), std::clamp(options.unlisted_share, 0.0, 1.0));
  std::vector<bool> listed(share.size(), false);
  for (std::size_t i = 0; i < kind.materials.size(); ++i) {
    const KindMaterial& m = kind.materials[i];
    const int c = table.find(m.material_class);
    if (c < 0) continue;
    const double s = i == 0 || !(m.max_share > 0.0) ? 1.0 : m.max_share;
    double& to = share[static_cast<std::size_t>(c)];
    to = listed[static_cast<std::size_t>(c)] ? std::max(to, s) : s;  // a class listed for two roles: the larger
    listed[static_cast<std::size_t>(c)] = true;
  }
  return share;
}

std::vector<std::string> fit_classes_to_kind(Projection& projection, const ObjectKind& kind, const MaterialTable& table,
                                             const std::vector<bool>& pinned, const PosteriorOptions& options) {
  std::vector<std::string> notes;
  const int n = table.size();
  if (n == 0 || kind.materials.empty()) return notes;
  const int main_class = table.find(kind.materials.front().material_class);
  if (main_class < 0) return notes;
  const std::vector<double> share = kind_class_shares(kind, table, options);
  // What a part may become: a class the kind lists, within its role's share
  // (the main role's any, a minor role's without a share of its own up to
  // minor_share); unlisted classes are no replacement.
  std::vector<double> takes(static_cast<std::size_t>(n), 0.0);
  for (std::size_t i = 0; i < kind.materials.size(); ++i) {
    const KindMaterial& m = kind.materials[i];
    const int c = table.find(m.material_class);
    if (c < 0) continue;
    const double s = i == 0 ? 1.0 : (m.max_share > 0.0 ? m.max_share : std::clamp(options.minor_share, 0.0, 1.0));
    takes[static_cast<std::size_t>(c)] = std::max(takes[static_cast<std::size_t>(c)], s);
  }
  std::vector<Part>& parts = projection.parts;
  double total = 0.0;
  std::vector<double> area(static_cast<std::size_t>(n), 0.0);
  for (const Part& p : parts)
    if (table.valid_label(p.label)) {
      area[static_cast<std::size_t>(p.label)] += p.area_m2;
      total += p.area_m2;
    }
  if (!(total > 0.0)) return notes;
  // The roles the kind gives each class, for the notes.
  auto roles_of = [&kind, &table](int c) {
    std::string roles;
    for (const KindMaterial& m : kind.materials)
      if (table.find(m.material_class) == c) roles += (roles.empty() ? "" : ", ") + m.role;
    return roles;
  };
  std::vector<bool> moved(parts.size(), false);
  for (std::size_t step = 0; step < parts.size(); ++step) {
    // The class furthest beyond its share.
    int over = -1;
    double worst = 1.0 + 1e-9;
    for (int c = 0; c < n; ++c) {
      const double s = share[static_cast<std::size_t>(c)];
      const double ratio = area[static_cast<std::size_t>(c)] / total / std::max(s, 1e-12);
      if (ratio > worst) {
        worst = ratio;
        over = c;
      }
    }
    if (over < 0) break;
    // Its largest part a person did not pin.
    int largest = -1;
    for (std::size_t i = 0; i < parts.size(); ++i)
      if (parts[i].label == over && !moved[i] && !(i < pinned.size() && pinned[i]) &&
          (largest < 0 || parts[i].area_m2 > parts[static_cast<std::size_t>(largest)].area_m2))
        largest = static_cast<int>(i);
    if (largest < 0) {  // every part of it is pinned or moved already: the person's call
      notes.push_back(table[over].name + " covers " + percent(area[static_cast<std::size_t>(over)] / total) +
                      " of the surface, more than " + kind.name + "'s " +
                      percent(share[static_cast<std::size_t>(over)]) +
                      ", but its parts are a person's corrections: kept");
      break;
    }
    Part& part = parts[static_cast<std::size_t>(largest)];
    const std::vector<double> p = part_class_probabilities(projection.votes, part, n);
    // The most probable class that takes this part within its share; the
    // kind's main class (no limit) when the votes name none.
    int to = main_class;
    double best = -1.0;
    for (int c = 0; c < n; ++c) {
      if (c == over) continue;
      const double fits = (area[static_cast<std::size_t>(c)] + part.area_m2) / total;
      if (fits > std::min(share[static_cast<std::size_t>(c)], takes[static_cast<std::size_t>(c)]) + 1e-9) continue;
      const double prob = p.empty() ? 0.0 : p[static_cast<std::size_t>(c)];
      if (prob > best || (prob == best && c == main_class)) {
        best = prob;
        to = c;
      }
    }
    if (!(best > 0.0)) to = main_class;
    const std::string roles = roles_of(over);
    notes.push_back("part " + std::to_string(largest) + " (" + percent(part.area_m2 / total) + " of the surface): " +
                    table[over].name + " -> " + table[to].name + ": " + (roles.empty() ? "an" : "a") + " " + kind.name +
                    "'s " + table[over].name + (roles.empty() ? "" : " (" + roles + ")") + " covers at most " +
                    percent(share[static_cast<std::size_t>(over)]) + " of it, and " + table[to].name + " is " +
                    (best > 0.0 ? "the most probable class of the part's votes that fits"
                                : std::string("the kind's main class (") + kind.materials.front().role + ")"));
    area[static_cast<std::size_t>(over)] -= part.area_m2;
    area[static_cast<std::size_t>(to)] += part.area_m2;
    part.label = to;
    for (int f : part.faces)
      if (f >= 0 && static_cast<std::size_t>(f) < projection.labels.label.size())
        projection.labels.label[static_cast<std::size_t>(f)] = to;
    moved[static_cast<std::size_t>(largest)] = true;
  }
  return notes;
}

}  // namespace g2p
