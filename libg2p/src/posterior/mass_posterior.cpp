// fit_mass_to_kind: the structure of every part chosen against the kind's
// mass (posterior.h); the posterior's median and 90 % interval by importance
// sampling.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <mutex>
#include <numeric>
#include <random>
#include <utility>

#include "g2p/posterior.h"

namespace g2p {

namespace {

std::string mm(double m) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g mm", m * 1000.0);
  return text;
}

std::string kg(double m) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g kg", m);
  return text;
}

std::string article(const std::string& noun) {
  const bool vowel = !noun.empty() && std::string("aeiou").find(noun.front()) != std::string::npos;
  return (vowel ? "an " : "a ") + noun;
}

// The standard normal quantile (Acklam's rational approximation, relative
// error below 1.2e-9), for the range's share of the log-normal.
double normal_quantile(double p) {
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  const double lo = 0.02425;
  if (p < lo) {
    const double q = std::sqrt(-2 * std::log(p));
    return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
           ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  }
  if (p > 1 - lo) return -normal_quantile(1 - p);
  const double q = p - 0.5, r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
         (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
}

// log of the likelihood of a total mass: a log-normal about `centre` (kg)
// with `sigma` in log units, up to a constant.
struct MassLikelihood {
  double centre = 1.0, sigma = 1.0;
  double operator()(double m) const {
    if (!(m > 0.0)) return -1e9;
    const double d = std::log(m / centre);
    return -0.5 * d * d / (sigma * sigma);
  }
};

// Weighted quantile of (value, weight) pairs, sorted by value in place.
double weighted_quantile(std::vector<std::pair<double, double>>& v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  double total = 0.0;
  for (const auto& x : v) total += x.second;
  if (!(total > 0.0)) return v[v.size() / 2].first;
  double run = 0.0;
  for (const auto& x : v) {
    run += x.second;
    if (run >= q * total) return x.first;
  }
  return v.back().first;
}

bool same(double a, double b) { return std::abs(a - b) <= 1e-6 * std::max(std::abs(a), std::abs(b)); }

// The walls a hollow part of class `c` may have: four from its range,
// spaced evenly in log.
std::vector<double> wall_set(const MaterialClass& c) {
  double lo = c.wall_range_m[0], hi = c.wall_range_m[1];
  if (!(lo > 0.0 && hi >= lo)) {
    lo = 0.5 * c.wall_thickness_m;
    hi = 2.0 * c.wall_thickness_m;
  }
  std::vector<double> walls;
  for (int i = 0; i < 4; ++i) walls.push_back(lo * std::pow(hi / lo, i / 3.0));
  return walls;
}

// Every way part `r` may be, the estimator's first.
std::vector<PartHypothesis> hypotheses_of(const PartReport& r, const Part& part, const CompletedPart& completed,
                                          const MaterialClass& c, const PosteriorOptions& o) {
  const PartProperties& p = r.properties;
  std::vector<PartHypothesis> out;
  PartHypothesis own;
  own.structure = p.structure;
  own.wall_thickness_m = p.wall_thickness_m;
  own.double_walled = p.double_walled;
  own.density_kg_m3 = p.density_kg_m3;
  own.mass_kg = r.mass.mass_kg - r.contents.mass_kg;
  own.estimated = true;
  own.words = p.structure == Structure::kHollow
                  ? "hollow, " + mm(p.wall_thickness_m) + (p.double_walled ? " walls modelled on both faces" : " walls")
                  : std::string("solid");
  out.push_back(own);
  const bool pinned = p.structure_source == ValueSource::kUser || p.density_source == ValueSource::kUser ||
                      p.thickness_source == ValueSource::kUser;
  if (pinned) return out;
  const double volume = completed.checks.volume_m3, area = part.area_m2;
  if (!(volume > 0.0) || !(area > 0.0)) return out;
  // A volume the input's faces disagree with: its own sheet is as likely as its closed volume.
  const bool doubtful = !completed.ok;
  std::vector<std::pair<double, double>> densities = {{p.density_kg_m3, 1.0}};
  for (double d : {c.density_min_kg_m3, c.density_max_kg_m3})
    if (d > 0.0 && !same(d, p.density_kg_m3)) densities.push_back({d, o.other_density_weight});
  const bool thin_measured = p.walls.rays > 0;
  for (const auto& density_and_weight : densities) {
    // Named, not bound: a lambda may not capture a structured binding before C++20.
    const double density = density_and_weight.first, density_weight = density_and_weight.second;
    auto add = [&](PartHypothesis h, double weight) {
      h.density_kg_m3 = density;
      h.prior = weight * density_weight;
      if (h.structure == own.structure && same(h.wall_thickness_m, own.wall_thickness_m) && same(h.fill, 1.0) &&
          h.double_walled == own.double_walled && same(density, own.density_kg_m3))
        return;  // the estimator's, already first
      out.push_back(h);
    };
    // Solid, or a fill of a light class (foam, stuffing) over a frame.
    PartHypothesis solid;
    solid.structure = Structure::kSolid;
    solid.mass_kg = volume * density;
    solid.words = "solid";
    const double solid_weight = own.structure == Structure::kSolid ? 1.0 : (doubtful ? 1.0 : o.other_structure_weight);
    add(solid, solid_weight);
    if (c.density_kg_m3 < 500.0)
      for (double fill : {0.25, 0.5}) {
        PartHypothesis h = solid;
        h.fill = fill;
        h.mass_kg = volume * density * fill;
        char words[48];
        std::snprintf(words, sizeof words, "solid, %.0f %% filled", 100.0 * fill);
        h.words = words;
        add(h, solid_weight * o.fill_weight);
      }
    // A single-walled shell from the class's walls.
    for (double t : wall_set(c)) {
      if (area * t >= volume) continue;                             // the shell would outweigh the volume
      if (thin_measured && p.walls.thickness_m <= 2 * t) continue;  // the walls would fill it
      PartHypothesis h;
      h.structure = Structure::kHollow;
      h.wall_thickness_m = t;
      h.mass_kg = area * t * density;
      h.words = "hollow, " + mm(t) + " walls";
      double weight =
          own.structure == Structure::kHollow ? o.other_wall_weight : (doubtful ? 1.0 : o.other_structure_weight);
      if (own.structure == Structure::kHollow && !own.double_walled && same(t, own.wall_thickness_m)) weight = 1.0;
      add(h, weight);
    }
  }
  return out;
}

// The part's other classes from its votes, drawn for the intervals only:
// each as the estimator's structure in that class (its nominal density; a
// shell of the class's wall), weighed by its votes against the part's own
// class. `shares` (per class; empty: no limit) is the kind's.
void add_other_classes(PartPosterior& pp, const PartReport& r, const CompletedPart& completed, double area_m2,
                       double share, const MaterialTable& table, const std::vector<double>& probability,
                       const std::vector<double>& shares) {
  const int own_label = r.properties.label;
  if (probability.size() != static_cast<std::size_t>(table.size()) || !table.valid_label(own_label)) return;
  const double volume = completed.checks.volume_m3;
  std::vector<int> others;
  double most = probability[static_cast<std::size_t>(own_label)];
  for (int c = 0; c < table.size(); ++c) {
    const std::size_t k = static_cast<std::size_t>(c);
    if (c == own_label || !(table[c].density_kg_m3 > 0.0) || probability[k] <= 0.0) continue;
    if (!shares.empty() && share > shares[k] + 1e-9) continue;  // the kind does not allow it so large
    others.push_back(c);
    most = std::max(most, probability[k]);
  }
  // The part's own class is at least as probable as any other: it won the
  // votes, or the kind or a neighbour chose it over the votes.
  double own_prior = 0.0;
  for (const PartHypothesis& h : pp.hypotheses) own_prior += h.prior;
  // A copy: the loop appends to pp.hypotheses, which may move its elements.
  const Structure own_structure = pp.hypotheses[0].structure;
  for (int c : others) {
    const MaterialClass& mc = table[c];
    PartHypothesis h;
    h.label = c;
    h.density_kg_m3 = mc.density_kg_m3;
    h.prior = own_prior * probability[static_cast<std::size_t>(c)] / most;
    const double t = mc.wall_thickness_m;
    if (own_structure == Structure::kHollow && t > 0.0 && area_m2 * t < volume) {
      h.structure = Structure::kHollow;
      h.wall_thickness_m = t;
      h.mass_kg = area_m2 * t * h.density_kg_m3;
      h.words = mc.name + ", hollow, " + mm(t) + " walls";
    } else if (volume > 0.0) {
      h.mass_kg = volume * h.density_kg_m3;
      h.words = mc.name + ", solid";
    } else {
      continue;
    }
    pp.hypotheses.push_back(h);
  }
}

Status check_options(const PosteriorOptions& o) {
  if (!(o.range_share > 0.0 && o.range_share < 1.0))
    return Status::InvalidArgument("posterior: range_share must lie in (0, 1)");
  for (const auto& [name, weight] : {std::pair<const char*, double>{"other_wall_weight", o.other_wall_weight},
                                     {"other_structure_weight", o.other_structure_weight},
                                     {"other_density_weight", o.other_density_weight},
                                     {"fill_weight", o.fill_weight},
                                     {"class_min_probability", o.class_min_probability}})
    if (!(weight > 0.0 && weight <= 1.0))
      return Status::InvalidArgument(std::string("posterior: ") + name + " must lie in (0, 1]");
  if (!(std::isfinite(o.size_exponent) && o.size_exponent >= 0.0))
    return Status::InvalidArgument("posterior: size_exponent must be a number >= 0");
  if (!(std::isfinite(o.bulk_density_kg_m3) && o.bulk_density_kg_m3 > 0.0))
    return Status::InvalidArgument("posterior: bulk_density_kg_m3 must be a positive number");
  if (!(std::isfinite(o.bulk_density_log_sd) && o.bulk_density_log_sd > 0.0))
    return Status::InvalidArgument("posterior: bulk_density_log_sd must be a positive number");
  return Status::Ok();
}

// What the object's total mass is believed to be: a log-normal about
// `centre_kg`, `range_kg` its central range_share.
struct Belief {
  double centre_kg = 1.0, sigma = 1.0;
  double range_kg[2] = {0.0, 0.0};
  std::string words;             // "a chair's 2.5-12 kg at 0.95 m"
  double hidden_fraction = 0.0;  // the kind's hidden mass, a share of the whole
  std::vector<double> shares;    // per class: the kind's largest share of the surface; empty: no limit
  bool decides = true;           // false: the estimate stands, the belief gives the intervals only
};

Result<MassPosterior> solve(const std::vector<Part>& parts, const Completion& completion, const MaterialTable& table,
                            const PropertiesReport& report, const Belief& belief, MassPosterior post,
                            const PosteriorOptions& o, const ClassEvidence& classes);

}  // namespace

Result<MassPosterior> fit_mass_to_kind(const std::vector<Part>& parts, const Completion& completion,
                                       const MaterialTable& table, const PropertiesReport& report,
                                       const ObjectKind& kind, double longest_side_m, const PosteriorOptions& o,
                                       const ClassEvidence& classes) {
  if (!(kind.mass_kg[0] > 0.0 && kind.mass_kg[1] >= kind.mass_kg[0]))
    return Status::InvalidArgument("posterior: the kind '" + kind.name + "' has no mass range");
  if (!(longest_side_m > 0.0) || !std::isfinite(longest_side_m))
    return Status::InvalidArgument("posterior: the object's longest side must be positive");
  G2P_RETURN_IF_ERROR(check_options(o));
  MassPosterior post;
  post.kind = kind.name;
  post.longest_side_m = longest_side_m;
  const double typical = kind.typical_longest_side_m > 0.0 ? kind.typical_longest_side_m : longest_side_m;
  // Within the kind's usual sizes. Far beyond them (kKindSizeTolerance) the
  // object is not of the kind as the table knows it (a toy train taken for a
  // train, a hammer called a refrigerator), and its mass is not judged; a
  // little beyond, it is judged at the nearest usual size.
  double judged_at = longest_side_m;
  const std::array<double, 2>& usual = kind.longest_side_m;
  if (usual[0] > 0.0 && usual[1] >= usual[0]) {
    if (longest_side_m < usual[0] / kKindSizeTolerance || longest_side_m > usual[1] * kKindSizeTolerance) {
      char why[256];
      std::snprintf(why, sizeof why,
                    "the object is %.3g m long, far outside %s's usual %.3g-%.3g m: its mass is not judged "
                    "against the kind's (is it one? check --object and the size given)",
                    longest_side_m, article(kind.name).c_str(), usual[0], usual[1]);
      return Status::InvalidArgument(why);
    }
    judged_at = std::clamp(judged_at, usual[0], usual[1]);
  }
  const double scale = std::pow(judged_at / typical, o.size_exponent);
  Belief belief;
  belief.range_kg[0] = kind.mass_kg[0] * scale;
  belief.range_kg[1] = kind.mass_kg[1] * scale;
  const double width = std::log(belief.range_kg[1] / belief.range_kg[0]);
  belief.centre_kg = std::sqrt(belief.range_kg[0] * belief.range_kg[1]);
  const double z = normal_quantile(0.5 + 0.5 * o.range_share);
  belief.sigma = std::max(0.05, width / (2.0 * z));
  char range[96];
  std::snprintf(range, sizeof range, "%.3g-%.3g kg at %.3g m", belief.range_kg[0], belief.range_kg[1], longest_side_m);
  belief.words = article(kind.name) + "'s " + range;
  for (const HiddenContent& h : kind.hidden) belief.hidden_fraction += h.mass_fraction;
  belief.shares = kind_class_shares(kind, table, o);
  return solve(parts, completion, table, report, belief, std::move(post), o, classes);
}

Result<MassPosterior> fit_mass_to_bulk_density(const std::vector<Part>& parts, const Completion& completion,
                                               const MaterialTable& table, const PropertiesReport& report,
                                               const PosteriorOptions& o, const ClassEvidence& classes) {
  G2P_RETURN_IF_ERROR(check_options(o));
  // The closed volume as scripts/mass_set/bulk_density.py measured it: every
  // part's that the complete stage closed, whether or not its checks passed
  // (the volumes the estimator weighs).
  double volume = 0.0;
  for (const CompletedPart& c : completion.parts)
    if (c.checks.volume_m3 > 0.0 && std::isfinite(c.checks.volume_m3)) volume += c.checks.volume_m3;
  if (!(volume > 0.0))
    return Status::InvalidArgument("posterior: no part closed, so the object has no volume to weigh by bulk density");
  Belief belief;
  belief.centre_kg = o.bulk_density_kg_m3 * volume;
  belief.sigma = o.bulk_density_log_sd;
  const double z = normal_quantile(0.5 + 0.5 * o.range_share);
  belief.range_kg[0] = belief.centre_kg * std::exp(-z * belief.sigma);
  belief.range_kg[1] = belief.centre_kg * std::exp(z * belief.sigma);
  char words[160];
  std::snprintf(words, sizeof words, "what everyday objects of its closed volume (%.3g m^3) weigh, %.3g-%.3g kg",
                volume, belief.range_kg[0], belief.range_kg[1]);
  belief.words = words;
  belief.decides = o.bulk_density_decides;
  MassPosterior post;
  return solve(parts, completion, table, report, belief, std::move(post), o, classes);
}

namespace {

Result<MassPosterior> solve(const std::vector<Part>& parts, const Completion& completion, const MaterialTable& table,
                            const PropertiesReport& report, const Belief& belief, MassPosterior post,
                            const PosteriorOptions& o, const ClassEvidence& classes) {
  post.judged_by = belief.words;
  post.range_kg[0] = belief.range_kg[0];
  post.range_kg[1] = belief.range_kg[1];
  MassLikelihood likelihood;
  likelihood.centre = belief.centre_kg;
  likelihood.sigma = belief.sigma;
  post.hidden_fraction = belief.hidden_fraction;

  // The hidden mass rides on a hollow body (estimate_properties_of_kind): a
  // share F of the whole, the visible mass times 1 / (1 - F).
  post.hidden_fraction = std::min(post.hidden_fraction, 0.9);
  double largest = 0.0;
  for (std::size_t i = 0; i < completion.parts.size(); ++i)
    if (completion.parts[i].ok && completion.parts[i].checks.volume_m3 > largest) {
      largest = completion.parts[i].checks.volume_m3;
      post.body = static_cast<int>(i);
    }
  bool hidden_added = false;
  for (const std::string& n : report.notes) hidden_added = hidden_added || n.rfind("hidden mass: ", 0) == 0;
  for (const PartReport& r : report.parts)
    if (r.part == post.body && r.contents.mass_kg > 0.0) hidden_added = true;
  // The report's notes say whether the kind's hidden mass was added; where it
  // was not (solid body, no cavity), it stays out of every total here too.
  if (!hidden_added) post.hidden_fraction = 0.0;

  double surface = 0.0;
  for (const Part& p : parts) surface += p.area_m2;
  double fixed_kg = 0.0;  // contents other than the kind's hidden mass (a person's fill)
  for (const PartReport& r : report.parts) {
    if (r.mass.mass_kg <= 0.0 || r.part < 0 || static_cast<std::size_t>(r.part) >= parts.size() ||
        static_cast<std::size_t>(r.part) >= completion.parts.size() || !table.valid_label(r.properties.label))
      continue;
    if (r.part != post.body) fixed_kg += r.contents.mass_kg;
    PartPosterior pp;
    pp.part = r.part;
    pp.hypotheses = hypotheses_of(r, parts[static_cast<std::size_t>(r.part)],
                                  completion.parts[static_cast<std::size_t>(r.part)], table[r.properties.label], o);
    pp.pinned = pp.hypotheses.size() == 1;
    const std::size_t index = static_cast<std::size_t>(r.part);
    const bool class_pinned = index < classes.pinned.size() && classes.pinned[index];
    if (!pp.pinned && !class_pinned && classes.votes != nullptr && surface > 0.0 && o.class_min_probability < 1.0) {
      std::vector<double> probability = part_class_probabilities(*classes.votes, parts[index], table.size());
      for (double& x : probability)
        if (x < o.class_min_probability) x = 0.0;
      add_other_classes(pp, r, completion.parts[index], parts[index].area_m2, parts[index].area_m2 / surface, table,
                        probability, belief.shares);
    }
    post.parts.push_back(std::move(pp));
  }
  if (post.parts.empty()) return Status::InvalidArgument("posterior: no part has a mass");
  const int body_index = [&] {
    for (std::size_t i = 0; i < post.parts.size(); ++i)
      if (post.parts[i].part == post.body) return static_cast<int>(i);
    return -1;
  }();
  // The object's total for choices `at` (index per part).
  auto hypothesis = [&post](std::size_t part, int h) -> const PartHypothesis& {
    return post.parts[part].hypotheses[static_cast<std::size_t>(h)];
  };
  // The object's total from the parts' visible mass, with the hidden mass
  // where the body is hollow.
  auto with_hidden = [&](double visible, const std::vector<int>& at) {
    const bool hollow_body =
        body_index >= 0 &&
        hypothesis(static_cast<std::size_t>(body_index), at[static_cast<std::size_t>(body_index)]).structure ==
            Structure::kHollow;
    return hollow_body ? visible / (1.0 - post.hidden_fraction) : visible;
  };
  auto total = [&](const std::vector<int>& at) {
    double visible = fixed_kg;
    for (std::size_t i = 0; i < post.parts.size(); ++i) visible += hypothesis(i, at[i]).mass_kg;
    return with_hidden(visible, at);
  };
  auto log_prior = [&](const std::vector<int>& at) {
    double s = 0.0;
    for (std::size_t i = 0; i < post.parts.size(); ++i) s += std::log(hypothesis(i, at[i]).prior);
    return s;
  };
  std::vector<int> at(post.parts.size(), 0);
  post.estimated_kg = total(at);
  auto in_range = [&post](double m) {
    return m >= post.range_kg[0] * (1 - 1e-9) && m <= post.range_kg[1] * (1 + 1e-9);
  };
  // Coordinate ascent on the log posterior, heaviest parts first; each sweep
  // moves each part to its best hypothesis with the others held.
  std::vector<std::size_t> order(post.parts.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return post.parts[a].hypotheses[0].mass_kg > post.parts[b].hypotheses[0].mass_kg;
  });
  // The sums kept as parts move, so that a sweep costs parts x hypotheses.
  double prior = log_prior(at), visible = fixed_kg;
  for (std::size_t i = 0; i < post.parts.size(); ++i) visible += hypothesis(i, 0).mass_kg;
  double best = prior + likelihood(with_hidden(visible, at));
  // An estimate the kind agrees with stands.
  for (int sweep = 0; sweep < 50 && belief.decides && !in_range(post.estimated_kg); ++sweep) {
    bool moved = false;
    for (std::size_t i : order) {
      const int was = at[i];
      const double rest_kg = visible - hypothesis(i, was).mass_kg;
      const double rest_prior = prior - std::log(hypothesis(i, was).prior);
      int pick = was;
      for (std::size_t h = 0; h < post.parts[i].hypotheses.size(); ++h) {
        if (post.parts[i].hypotheses[h].label >= 0) continue;  // another class: the intervals' only
        at[i] = static_cast<int>(h);
        const PartHypothesis& c = hypothesis(i, at[i]);
        const double score = rest_prior + std::log(c.prior) + likelihood(with_hidden(rest_kg + c.mass_kg, at));
        if (score > best + 1e-12) {
          best = score;
          pick = static_cast<int>(h);
        }
      }
      at[i] = pick;
      visible = rest_kg + hypothesis(i, pick).mass_kg;
      prior = rest_prior + std::log(hypothesis(i, pick).prior);
      moved = moved || pick != was;
    }
    if (!moved) break;
  }
  post.mass_kg = total(at);
  post.in_range = in_range(post.mass_kg);

  const std::string& whose = post.judged_by;
  const std::string why = post.kind.empty() ? "" : " (the kind's mass)";
  for (std::size_t i = 0; i < post.parts.size(); ++i) {
    PartPosterior& pp = post.parts[i];
    pp.chosen = at[i];
    if (pp.chosen == 0) continue;
    std::vector<int> reverted = at;
    reverted[i] = 0;
    const double before = total(reverted);
    const PartHypothesis& h = pp.hypotheses[static_cast<std::size_t>(pp.chosen)];
    const PartHypothesis& own = pp.hypotheses[0];
    char density[48];
    std::snprintf(density, sizeof density, "%.0f kg/m^3", h.density_kg_m3);
    std::string cls;
    for (const PartReport& r : report.parts)
      if (r.part == pp.part) cls = table[r.properties.label].name;
    pp.note = h.words + " at " + density + ": " + cls + " " + own.words +
              (same(own.density_kg_m3, h.density_kg_m3) ? "" : " at its nominal density") + " would make the object " +
              kg(before) + ", " +
              (before > post.range_kg[1]   ? "beyond "
               : before < post.range_kg[0] ? "short of "
                                           : "within ") +
              whose + why;
    post.notes.push_back("part " + std::to_string(pp.part) + " (" + cls + "): " + pp.note);
  }
  if (!post.in_range && !belief.decides) {
    post.notes.push_back("the object weighs " + kg(post.mass_kg) +
                         (post.mass_kg > post.range_kg[1] ? ", beyond " : ", short of ") + whose +
                         "; the estimate stands (the belief gives the interval only)");
  } else if (!post.in_range) {
    // The part that breaks it: the heaviest when too heavy, the one that could
    // gain most when too light.
    std::size_t worst = 0;
    double worst_kg = -1.0;
    for (std::size_t i = 0; i < post.parts.size(); ++i) {
      double extreme = post.mass_kg > post.range_kg[1] ? 1e300 : 0.0;
      for (const PartHypothesis& h : post.parts[i].hypotheses)
        if (h.label < 0)
          extreme = post.mass_kg > post.range_kg[1] ? std::min(extreme, h.mass_kg) : std::max(extreme, h.mass_kg);
      if (extreme > worst_kg) {
        worst_kg = extreme;
        worst = i;
      }
    }
    const PartPosterior& w = post.parts[worst];
    std::string cls;
    for (const PartReport& r : report.parts)
      if (r.part == w.part) cls = table[r.properties.label].name;
    post.notes.push_back(
        "no assignment of the parts' structures reaches " + whose + ": the object weighs " + kg(post.mass_kg) +
        (post.mass_kg > post.range_kg[1]
             ? "; part " + std::to_string(w.part) + " (" + cls + ") alone weighs at least " + kg(worst_kg)
             : "; part " + std::to_string(w.part) + " (" + cls + ") weighs at most " + kg(worst_kg)) +
        " (check its class, the object's size or what it is)");
  }

  // Importance sampling: hypotheses drawn by their priors, weighed by the
  // likelihood of the total they make.
  if (o.samples > 0) {
    std::mt19937 rng(o.seed);
    std::vector<std::discrete_distribution<int>> draw;
    for (const PartPosterior& pp : post.parts) {
      std::vector<double> w;
      for (const PartHypothesis& h : pp.hypotheses) w.push_back(h.prior);
      draw.emplace_back(w.begin(), w.end());
    }
    const std::size_t n = static_cast<std::size_t>(o.samples), count = post.parts.size();
    std::vector<std::pair<double, double>> totals(n);
    std::vector<std::uint16_t> drawn(n * count);  // sample s, part i: its hypothesis (at most a few dozen)
    std::vector<int> sample(count, 0);
    double sum = 0.0, sum2 = 0.0;
    for (std::size_t s = 0; s < n; ++s) {
      for (std::size_t i = 0; i < count; ++i) {
        sample[i] = draw[i](rng);
        drawn[s * count + i] = static_cast<std::uint16_t>(sample[i]);
      }
      const double m = total(sample);
      const double w = std::exp(likelihood(m));
      sum += w;
      sum2 += w * w;
      totals[s] = {m, w};
    }
    post.effective_samples = sum2 > 0.0 ? sum * sum / sum2 : 0.0;
    if (!(sum > 0.0))  // no sample near the range: the prior's spread
      for (auto& t : totals) t.second = 1.0;
    std::vector<double> weight(n);
    for (std::size_t s = 0; s < n; ++s) weight[s] = totals[s].second;
    post.median_kg = weighted_quantile(totals, 0.5);
    post.p05_kg = weighted_quantile(totals, 0.05);
    post.p95_kg = weighted_quantile(totals, 0.95);
    std::vector<std::pair<double, double>> each(n);
    for (std::size_t i = 0; i < count; ++i) {
      for (std::size_t s = 0; s < n; ++s) each[s] = {hypothesis(i, drawn[s * count + i]).mass_kg, weight[s]};
      PartPosterior& pp = post.parts[i];
      pp.median_kg = weighted_quantile(each, 0.5);
      pp.p05_kg = weighted_quantile(each, 0.05);
      pp.p95_kg = weighted_quantile(each, 0.95);
    }
  }
  return post;
}

}  // namespace

namespace {

class PosteriorEstimator final : public PropertyEstimator {
 public:
  PosteriorEstimator(const PropertyEstimator& base, const MassPosterior& posterior)
      : base_(base), source_(posterior.kind.empty() ? "everyday objects' mass: " : "the kind's mass: ") {
    for (const PartPosterior& p : posterior.parts)
      if (p.chosen > 0) chosen_[p.part] = &p;
  }
  Result<PartProperties> estimate(const PropertyInput& in) const override {
    Result<PartProperties> r = base_.estimate(in);
    if (!r.ok() || in.part == nullptr || in.all_parts == nullptr) return r;
    const int index = static_cast<int>(in.part - in.all_parts->data());
    const auto it = chosen_.find(index);
    if (it == chosen_.end()) return r;
    const PartPosterior& pp = *it->second;
    const PartHypothesis& h = pp.hypotheses[static_cast<std::size_t>(pp.chosen)];
    PartProperties& p = *r;
    const double nominal = p.density_kg_m3;
    p.structure = h.structure;
    p.wall_thickness_m = h.structure == Structure::kHollow ? h.wall_thickness_m : p.wall_thickness_m;
    p.double_walled = h.structure == Structure::kHollow && h.double_walled;
    const double density = h.density_kg_m3 * h.fill;
    if (nominal > 0.0 && !same(density, nominal)) {
      p.density_min_kg_m3 *= density / nominal;
      p.density_max_kg_m3 *= density / nominal;
      p.density_min_kg_m3 = std::min(p.density_min_kg_m3, density);
      p.density_max_kg_m3 = std::max(p.density_max_kg_m3, density);
      p.density_source = ValueSource::kKind;
    }
    p.density_kg_m3 = density;
    p.structure_source = ValueSource::kKind;
    if (h.structure == Structure::kHollow) p.thickness_source = ValueSource::kKind;
    p.notes.push_back(source_ + pp.note);
    return r;
  }

 private:
  const PropertyEstimator& base_;
  const std::string source_;
  std::map<int, const PartPosterior*> chosen_;
};

}  // namespace

std::unique_ptr<PropertyEstimator> make_posterior_estimator(const PropertyEstimator& base,
                                                            const MassPosterior& posterior) {
  return std::make_unique<PosteriorEstimator>(base, posterior);
}

void apply_intervals(const MassPosterior& posterior, PropertiesReport& report) {
  for (PartReport& r : report.parts)
    for (const PartPosterior& p : posterior.parts)
      if (p.part == r.part && p.median_kg > 0.0) {
        r.mass_median_kg = p.median_kg;
        r.mass_p05_kg = p.p05_kg;
        r.mass_p95_kg = p.p95_kg;
      }
  if (posterior.median_kg > 0.0) {
    report.mass_median_kg = posterior.median_kg;
    report.mass_p05_kg = posterior.p05_kg;
    report.mass_p95_kg = posterior.p95_kg;
  }
  report.mass_judged_by = posterior.judged_by;
  if (!posterior.kind.empty()) {
    report.kind_range_kg[0] = posterior.range_kg[0];
    report.kind_range_kg[1] = posterior.range_kg[1];
  }
  const std::string source = posterior.kind.empty() ? "everyday objects' mass: " : "kind's mass: ";
  for (const std::string& n : posterior.notes) report.notes.push_back(source + n);
}

}  // namespace g2p
