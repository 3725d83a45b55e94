// The kind's classes by share and the kind's mass posterior (posterior.h).
#include "g2p/posterior.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "g2p/export.h"
#include "g2p/pipeline.h"
#include "support/test_data.h"

namespace g2p {
namespace {

const MaterialTable& table() { return MaterialTable::paper_default(); }
int cls(const char* name) { return table().find(name); }

const ObjectKind& kind(const char* name) {
  const ObjectTable& objects = ObjectTable::shipped();
  const int k = objects.find(name);
  EXPECT_GE(k, 0) << name;
  return objects.kinds()[static_cast<std::size_t>(k)];
}

TEST(KindClassShares, ACarsTyresAreASmallShareItsBodyAny) {
  const std::vector<double> share = kind_class_shares(kind("car"), table());
  EXPECT_DOUBLE_EQ(share[static_cast<std::size_t>(cls("Metal"))], 1.0);   // the body, the main role
  EXPECT_DOUBLE_EQ(share[static_cast<std::size_t>(cls("Rubber"))], 0.2);  // the tyres (the object table)
  EXPECT_DOUBLE_EQ(share[static_cast<std::size_t>(cls("Glass"))], 1.0);   // windows: the table gives no share
  EXPECT_DOUBLE_EQ(share[static_cast<std::size_t>(cls("Stone"))], 1.0);   // not listed: no limit by default
  PosteriorOptions strict;
  strict.unlisted_share = 0.1;
  EXPECT_DOUBLE_EQ(kind_class_shares(kind("car"), table(), strict)[static_cast<std::size_t>(cls("Stone"))], 0.1);
}

// Three parts of one face each; part 0's face voted mostly Rubber, then Metal.
Projection car_projection(double body_area) {
  Projection p;
  const int n = table().size();
  p.votes.num_classes = n;
  p.votes.row = {0, 1, 2};
  p.votes.histogram.assign(static_cast<std::size_t>(3 * n), 0.0f);
  p.votes.histogram[static_cast<std::size_t>(0 * n + cls("Rubber"))] = 80;
  p.votes.histogram[static_cast<std::size_t>(0 * n + cls("Glass"))] = 5;
  p.votes.histogram[static_cast<std::size_t>(0 * n + cls("Metal"))] = 15;
  p.votes.histogram[static_cast<std::size_t>(1 * n + cls("Rubber"))] = 100;
  p.votes.histogram[static_cast<std::size_t>(2 * n + cls("Glass"))] = 100;
  p.votes.total = {100, 100, 100};
  p.labels.label = {cls("Rubber"), cls("Rubber"), cls("Glass")};
  p.parts = {{cls("Rubber"), {0}, body_area}, {cls("Rubber"), {1}, 0.1}, {cls("Glass"), {2}, 0.2}};
  p.face_part = {0, 1, 2};
  return p;
}

TEST(FitClassesToKind, ACarBodyLabelledRubberTakesItsNextMostProbableClassTheKindAllows) {
  Projection p = car_projection(0.7);
  const std::vector<std::string> notes = fit_classes_to_kind(p, kind("car"), table());
  ASSERT_EQ(notes.size(), 1u);
  // Metal (15 votes), the body's class; Glass (5), the windows', could not take 70 % of a car.
  EXPECT_EQ(p.parts[0].label, cls("Metal"));
  EXPECT_EQ(p.labels.label[0], cls("Metal"));
  EXPECT_EQ(p.parts[1].label, cls("Rubber"));  // a tyre: 10 % of the surface, within a car's 20 %
  EXPECT_EQ(p.parts[2].label, cls("Glass"));
  EXPECT_NE(notes[0].find("part 0"), std::string::npos) << notes[0];
  EXPECT_NE(notes[0].find("Rubber -> Metal"), std::string::npos) << notes[0];
  EXPECT_NE(notes[0].find("tyres"), std::string::npos) << notes[0];
}

TEST(FitClassesToKind, ClassesWithinTheirSharesAndAPersonsClassesStay) {
  Projection p = car_projection(0.05);  // the Rubber parts cover 0.15 / 0.35 = 43 %: too much for tyres...
  p.parts[2].area_m2 = 0.85;            // ...but 0.15 / 1.0 is a car's tyres, with a body of metal
  p.parts[2].label = p.labels.label[2] = cls("Metal");
  EXPECT_TRUE(fit_classes_to_kind(p, kind("car"), table()).empty());
  EXPECT_EQ(p.parts[0].label, cls("Rubber"));

  // A kind that gives no shares changes nothing: a hammer of Rubber is a rubber mallet.
  Projection mallet = car_projection(0.7);
  EXPECT_TRUE(fit_classes_to_kind(mallet, kind("hammer"), table()).empty());
  EXPECT_EQ(mallet.parts[0].label, cls("Rubber"));

  Projection pinned = car_projection(0.7);
  const std::vector<std::string> notes = fit_classes_to_kind(pinned, kind("car"), table(), {true, false, false});
  // The pinned body stays Rubber; the tyre alone cannot bring the share down, and is moved too.
  EXPECT_EQ(pinned.parts[0].label, cls("Rubber"));
  ASSERT_FALSE(notes.empty());
  EXPECT_NE(notes.back().find("a person's corrections"), std::string::npos) << notes.back();
}

// One part of `label`, weighed solid or hollow by the table's values, with a
// closed volume and a surface area of its own.
struct Weighed {
  std::vector<Part> parts;
  Completion completion;
  PropertiesReport report;

  void add(int label, double volume_m3, double area_m2, Structure structure = Structure::kSolid,
           ValueSource source = ValueSource::kTable) {
    const MaterialClass& c = table()[label];
    const int index = static_cast<int>(parts.size());
    parts.push_back({label, {index}, area_m2});
    CompletedPart done;
    done.part = index;
    done.label = label;
    done.ok = true;
    done.checks.volume_m3 = volume_m3;
    done.checks.area_m2 = area_m2;
    completion.parts.push_back(done);
    PartReport r;
    r.part = index;
    r.completed_ok = true;
    r.properties.label = label;
    r.properties.density_kg_m3 = c.density_kg_m3;
    r.properties.density_min_kg_m3 = c.density_min_kg_m3;
    r.properties.density_max_kg_m3 = c.density_max_kg_m3;
    r.properties.structure = structure;
    r.properties.wall_thickness_m = c.wall_thickness_m;
    r.properties.structure_source = source;
    r.mass.mass_kg =
        structure == Structure::kSolid ? volume_m3 * c.density_kg_m3 : area_m2 * c.wall_thickness_m * c.density_kg_m3;
    report.parts.push_back(r);
    report.object.mass_kg += r.mass.mass_kg;
  }
};

TEST(FitMassToKind, ASolidWoodChairFrameBecomesWhatAChairWeighs) {
  Weighed w;
  w.add(cls("Wood"), 0.025, 2.2);   // a carved frame, 17.5 kg solid
  w.add(cls("Fabric"), 0.03, 1.0);  // the seat's upholstery, 3 kg
  ASSERT_GT(w.report.object.mass_kg, 20.0);
  Result<MassPosterior> post = fit_mass_to_kind(w.parts, w.completion, table(), w.report, kind("chair"), 0.95);
  ASSERT_TRUE(post.ok()) << post.status().to_string();
  // The table's 2.5-12 kg at a chair's 0.88 m, scaled by (0.95 / 0.88)^2.
  const double scale = std::pow(0.95 / kind("chair").typical_longest_side_m, 2.0);
  EXPECT_NEAR(post->range_kg[0], 2.5 * scale, 1e-9);
  EXPECT_NEAR(post->range_kg[1], 12 * scale, 1e-9);
  EXPECT_TRUE(post->in_range) << post->mass_kg;
  EXPECT_NEAR(post->estimated_kg, w.report.object.mass_kg, 1e-9);
  ASSERT_EQ(post->parts.size(), 2u);
  const PartPosterior& frame = post->parts[0];
  ASSERT_NE(frame.chosen, 0);  // not the estimator's solid at 700 kg/m^3
  const PartHypothesis& h = frame.hypotheses[static_cast<std::size_t>(frame.chosen)];
  // Physical: the part weighs its own volume or shell times its density, never a scaled total.
  const double physical =
      h.structure == Structure::kHollow ? 2.2 * h.wall_thickness_m * h.density_kg_m3 : 0.025 * h.density_kg_m3 * h.fill;
  EXPECT_NEAR(h.mass_kg, physical, 1e-9);
  EXPECT_NE(frame.note.find("chair"), std::string::npos) << frame.note;
  EXPECT_NE(frame.note.find("beyond"), std::string::npos) << frame.note;
  // The interval: ordered, and the median inside the kind's range.
  EXPECT_LE(post->p05_kg, post->median_kg);
  EXPECT_LE(post->median_kg, post->p95_kg);
  EXPECT_GE(post->median_kg, post->range_kg[0]);
  EXPECT_LE(post->median_kg, post->range_kg[1]);
  EXPECT_GT(post->effective_samples, 100.0);
}

TEST(FitMassToKind, AMassInTheKindsRangeIsKeptExactly) {
  Weighed w;
  w.add(cls("Wood"), 2.1e-4, 0.03);      // a hammer's handle, 0.147 kg
  w.add(cls("Metal"), 1.68e-4, 0.0208);  // its head, 1.31 kg
  Result<MassPosterior> post = fit_mass_to_kind(w.parts, w.completion, table(), w.report, kind("hammer"), 0.33);
  ASSERT_TRUE(post.ok()) << post.status().to_string();
  EXPECT_FALSE(post->changed());
  EXPECT_DOUBLE_EQ(post->mass_kg, w.report.object.mass_kg);
  EXPECT_TRUE(post->notes.empty());
}

TEST(FitMassToKind, APersonsStructureStaysAndWhatBreaksTheRangeIsNamed) {
  Weighed w;
  w.add(cls("Metal"), 0.2, 3.0, Structure::kSolid, ValueSource::kUser);  // 1.56 t of steel, a person's
  w.add(cls("Plastic"), 0.001, 0.1, Structure::kHollow);
  Result<MassPosterior> post = fit_mass_to_kind(w.parts, w.completion, table(), w.report, kind("chair"), 0.9);
  ASSERT_TRUE(post.ok());
  EXPECT_TRUE(post->parts[0].pinned);
  EXPECT_EQ(post->parts[0].chosen, 0);
  EXPECT_FALSE(post->in_range);
  ASSERT_FALSE(post->notes.empty());
  EXPECT_NE(post->notes.back().find("no assignment"), std::string::npos) << post->notes.back();
  EXPECT_NE(post->notes.back().find("part 0 (Metal)"), std::string::npos) << post->notes.back();
}

TEST(FitMassToKind, BadInputIsAnErrorNamingIt) {
  Weighed w;
  w.add(cls("Wood"), 0.01, 0.5);
  EXPECT_FALSE(fit_mass_to_kind(w.parts, w.completion, table(), w.report, kind("chair"), 0.0).ok());
  const Status far = fit_mass_to_kind(w.parts, w.completion, table(), w.report, kind("chair"), 5.0).status();
  EXPECT_NE(far.message().find("far outside a chair's usual"), std::string::npos) << far.message();
  PosteriorOptions bad;
  bad.fill_weight = -1.0;
  const Status weight = fit_mass_to_kind(w.parts, w.completion, table(), w.report, kind("chair"), 0.9, bad).status();
  EXPECT_NE(weight.message().find("fill_weight"), std::string::npos) << weight.message();
  ObjectKind massless = kind("chair");
  massless.mass_kg = {0.0, 0.0};
  const Status s = fit_mass_to_kind(w.parts, w.completion, table(), w.report, massless, 0.9).status();
  EXPECT_NE(s.message().find("mass range"), std::string::npos) << s.message();
}

// Votes for one face per part: part `part`'s face voted `share` for `other`,
// the rest for its own class.
FaceVotes votes_for(const Weighed& w, std::size_t part, int other, float share) {
  FaceVotes v;
  v.num_classes = table().size();
  for (std::size_t i = 0; i < w.parts.size(); ++i) {
    v.row.push_back(static_cast<int>(i));
    std::vector<float> row(static_cast<std::size_t>(v.num_classes), 0.0f);
    row[static_cast<std::size_t>(w.parts[i].label)] = i == part ? 100.0f * (1.0f - share) : 100.0f;
    if (i == part) row[static_cast<std::size_t>(other)] = 100.0f * share;
    v.histogram.insert(v.histogram.end(), row.begin(), row.end());
    v.total.push_back(100.0f);
  }
  return v;
}

TEST(FitMassToBulkDensity, AnEstimateLikeEverydayObjectsStandsWithAnInterval) {
  Weighed w;
  w.add(cls("Wood"), 0.05, 1.2);  // a wooden cabinet's carcass, solid: 35 kg over 0.05 m^3
  Result<MassPosterior> post = fit_mass_to_bulk_density(w.parts, w.completion, table(), w.report);
  ASSERT_TRUE(post.ok()) << post.status().to_string();
  EXPECT_TRUE(post->kind.empty());
  EXPECT_FALSE(post->changed());
  EXPECT_DOUBLE_EQ(post->mass_kg, w.report.object.mass_kg);
  EXPECT_TRUE(post->in_range);
  // The belief: everyday objects' bulk density over the closed volume, its central 90 %.
  const PosteriorOptions d;
  EXPECT_NEAR(std::sqrt(post->range_kg[0] * post->range_kg[1]), d.bulk_density_kg_m3 * 0.05, 1e-6);
  EXPECT_NEAR(std::log(post->range_kg[1] / post->range_kg[0]), 2 * 1.6449 * d.bulk_density_log_sd, 1e-3);
  EXPECT_NE(post->judged_by.find("everyday objects"), std::string::npos) << post->judged_by;
  EXPECT_LE(post->p05_kg, post->median_kg);
  EXPECT_LE(post->median_kg, post->p95_kg);
  EXPECT_LT(post->p05_kg, post->p95_kg);  // the structures and densities the part may have
  PropertiesReport report = w.report;
  apply_intervals(*post, report);
  EXPECT_EQ(report.mass_judged_by, post->judged_by);
  EXPECT_DOUBLE_EQ(report.kind_range_kg[1], 0.0);  // no kind's range
  EXPECT_DOUBLE_EQ(report.mass_median_kg, post->median_kg);
}

TEST(FitMassToBulkDensity, AFarTooLightEstimateIsNamedOrTakesAHeavierStructureWhenAllowed) {
  Weighed w;
  w.add(cls("Metal"), 0.5, 3.8, Structure::kHollow);  // a 0.5 m^3 closed volume as sheet metal
  const PosteriorOptions d;                           // beyond the central 90 % of everyday objects' bulk density
  ASSERT_LT(w.report.object.mass_kg / 0.5, d.bulk_density_kg_m3 * std::exp(-1.6449 * d.bulk_density_log_sd));
  // By default the belief gives the interval only: the estimate stands and is named.
  Result<MassPosterior> post = fit_mass_to_bulk_density(w.parts, w.completion, table(), w.report);
  ASSERT_TRUE(post.ok()) << post.status().to_string();
  EXPECT_FALSE(post->changed());
  EXPECT_DOUBLE_EQ(post->mass_kg, w.report.object.mass_kg);
  ASSERT_EQ(post->notes.size(), 1u);
  EXPECT_NE(post->notes[0].find("the estimate stands"), std::string::npos) << post->notes[0];
  EXPECT_NE(post->notes[0].find("short of what everyday objects"), std::string::npos) << post->notes[0];
  EXPECT_GT(post->median_kg, post->estimated_kg);  // the interval leans to what such objects weigh
  // Allowed to decide, it takes a heavier structure, in words.
  PosteriorOptions deciding;
  deciding.bulk_density_decides = true;
  post = fit_mass_to_bulk_density(w.parts, w.completion, table(), w.report, deciding);
  ASSERT_TRUE(post.ok());
  ASSERT_TRUE(post->changed());
  EXPECT_GT(post->mass_kg, post->estimated_kg);
  EXPECT_NE(post->parts[0].note.find("short of what everyday objects"), std::string::npos) << post->parts[0].note;
}

TEST(FitMassToBulkDensity, NoClosedPartIsAnError) {
  Weighed w;
  w.add(cls("Wood"), 0.05, 1.2);
  w.completion.parts[0].checks.volume_m3 = 0.0;
  const Status s = fit_mass_to_bulk_density(w.parts, w.completion, table(), w.report).status();
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("no part closed"), std::string::npos) << s.message();
  PosteriorOptions bad;
  bad.bulk_density_log_sd = 0.0;
  w.completion.parts[0].checks.volume_m3 = 0.05;
  const Status sd = fit_mass_to_bulk_density(w.parts, w.completion, table(), w.report, bad).status();
  EXPECT_NE(sd.message().find("bulk_density_log_sd"), std::string::npos) << sd.message();
}

TEST(ClassEvidence, APartsOtherProbableClassWidensTheIntervalNotTheChoice) {
  Weighed w;
  w.add(cls("Wood"), 1e-4, 0.015);  // a cabinet's knob, 70 g of wood; its faces 45 % Metal (a steel knob, 0.78 kg)
  w.add(cls("Wood"), 0.05, 1.2);    // the cabinet, 35 kg: either knob is an everyday cabinet
  const FaceVotes votes = votes_for(w, 0, cls("Metal"), 0.45f);
  const std::vector<double> p = part_class_probabilities(votes, w.parts[0], table().size());
  ASSERT_EQ(p.size(), static_cast<std::size_t>(table().size()));
  EXPECT_NEAR(p[static_cast<std::size_t>(cls("Metal"))], 0.45, 1e-6);
  Result<MassPosterior> certain = fit_mass_to_bulk_density(w.parts, w.completion, table(), w.report);
  ClassEvidence evidence;
  evidence.votes = &votes;
  Result<MassPosterior> doubtful = fit_mass_to_bulk_density(w.parts, w.completion, table(), w.report, {}, evidence);
  ASSERT_TRUE(certain.ok() && doubtful.ok());
  // The chosen assignment keeps the part's class and mass...
  EXPECT_FALSE(doubtful->changed());
  EXPECT_DOUBLE_EQ(doubtful->mass_kg, certain->mass_kg);
  // ...the interval draws a steel knob too.
  bool steel = false;
  for (const PartHypothesis& h : doubtful->parts[0].hypotheses) steel |= h.label == cls("Metal");
  EXPECT_TRUE(steel);
  EXPECT_GT(doubtful->parts[0].p95_kg, 2.0 * certain->parts[0].p95_kg);
  // A class a person gave is not in doubt; a vote share under class_min_probability is not drawn.
  evidence.pinned = {true, false};
  Result<MassPosterior> pinned = fit_mass_to_bulk_density(w.parts, w.completion, table(), w.report, {}, evidence);
  ASSERT_TRUE(pinned.ok());
  EXPECT_EQ(pinned->parts[0].hypotheses.size(), certain->parts[0].hypotheses.size());
  PosteriorOptions strict;
  strict.class_min_probability = 0.5;
  evidence.pinned.clear();
  Result<MassPosterior> few = fit_mass_to_bulk_density(w.parts, w.completion, table(), w.report, strict, evidence);
  ASSERT_TRUE(few.ok());
  EXPECT_EQ(few->parts[0].hypotheses.size(), certain->parts[0].hypotheses.size());
}

TEST(ClassEvidence, EveryOtherProbableClassIsDrawnAfterThePartsOwn) {
  // Votes spread over five classes: the part's hypotheses grow by four while
  // its own stay first (a regression: growing them once read a moved element).
  Weighed w;
  w.add(cls("Wood"), 1e-3, 0.08);
  FaceVotes votes = votes_for(w, 0, cls("Metal"), 0.15f);
  const std::size_t n = static_cast<std::size_t>(votes.num_classes);
  for (const char* name : {"Plastic", "Glass", "Fabric"}) {
    votes.histogram[static_cast<std::size_t>(cls(name))] = 15.0f;
    votes.histogram[static_cast<std::size_t>(cls("Wood"))] -= 15.0f;
  }
  ASSERT_EQ(votes.histogram.size(), n);
  Result<MassPosterior> certain = fit_mass_to_bulk_density(w.parts, w.completion, table(), w.report);
  ClassEvidence evidence;
  evidence.votes = &votes;
  Result<MassPosterior> spread = fit_mass_to_bulk_density(w.parts, w.completion, table(), w.report, {}, evidence);
  ASSERT_TRUE(certain.ok() && spread.ok());
  const std::vector<PartHypothesis>& own = certain->parts[0].hypotheses;
  const std::vector<PartHypothesis>& all = spread->parts[0].hypotheses;
  ASSERT_EQ(all.size(), own.size() + 4);
  for (std::size_t i = 0; i < own.size(); ++i) EXPECT_DOUBLE_EQ(all[i].mass_kg, own[i].mass_kg);
  std::vector<int> drawn;
  for (std::size_t i = own.size(); i < all.size(); ++i) drawn.push_back(all[i].label);
  std::sort(drawn.begin(), drawn.end());
  std::vector<int> expected = {cls("Metal"), cls("Plastic"), cls("Glass"), cls("Fabric")};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(drawn, expected);
  EXPECT_DOUBLE_EQ(spread->mass_kg, certain->mass_kg);
}

}  // namespace
}  // namespace g2p

namespace g2p {
namespace {

// Appends closed, outward boxes to an OBJ, given in libg2p's frame (+Z up;
// OBJ's +Y is up, so each vertex is written as x, z, -y).
struct ObjBoxes {
  std::ofstream& obj;
  int base = 0;
  void operator()(double x0, double y0, double z0, double x1, double y1, double z1) {
    for (int i = 0; i < 8; ++i)
      obj << "v " << (i & 1 ? x1 : x0) << " " << (i & 4 ? z1 : z0) << " " << -(i & 2 ? y1 : y0) << "\n";
    const int quads[6][4] = {{1, 3, 4, 2}, {5, 6, 8, 7}, {1, 2, 6, 5}, {3, 7, 8, 4}, {1, 5, 7, 3}, {2, 4, 8, 6}};
    for (const auto& q : quads)
      obj << "f " << base + q[0] << " " << base + q[1] << " " << base + q[2] << "\nf " << base + q[0] << " "
          << base + q[2] << " " << base + q[3] << "\n";
    base += 8;
  }
};

// A chair of boxes as an OBJ: four 8 cm wooden legs, an 8 cm seat board and
// back, and a fabric cushion on the seat; 1.03 m tall.
std::string write_box_chair(const std::string& dir) {
  std::filesystem::create_directories(dir);
  std::ofstream mtl(dir + "/chair.mtl");
  mtl << "newmtl wood\nKd 0.6 0.4 0.2\nnewmtl fabric\nKd 0.8 0.1 0.4\n";
  std::ofstream obj(dir + "/chair.obj");
  obj << "mtllib chair.mtl\n";
  ObjBoxes box{obj};
  obj << "usemtl wood\n";
  for (double x : {0.0, 0.42})
    for (double y : {0.0, 0.42}) box(x, y, 0.0, x + 0.08, y + 0.08, 0.45);
  box(0.0, 0.0, 0.45, 0.5, 0.5, 0.53);   // seat board
  box(0.0, 0.42, 0.53, 0.5, 0.5, 1.03);  // back
  obj << "usemtl fabric\n";
  box(0.03, 0.03, 0.53, 0.42, 0.42, 0.61);  // cushion
  return dir + "/chair.obj";
}

TEST(KindPosterior, AChairOfSolidBoardsWeighsAsAChairAndMujocoWeighsItsPartsWhereTheyAre) {
  const std::string dir = test::scratch_dir("KindPosteriorChair");
  const std::string chair = write_box_chair(dir);
  PipelineOptions o;
  o.views.width = o.views.height = 192;                 // enough for two materials by name
  o.completer = {"partition", {{"resolution", "48"}}};  // boxes need no finer grid
  o.identifier = {"object", {}};
  o.object = "chair";
  o.kind_posterior = false;
  Result<PipelineResult> plain = Pipeline(o).run_file(chair);
  ASSERT_TRUE(plain.ok()) << plain.status().to_string();
  o.kind_posterior = true;
  Result<PipelineResult> r = Pipeline(o).run_file(chair);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  const double range_lo = r->properties.kind_range_kg[0], range_hi = r->properties.kind_range_kg[1];
  ASSERT_GT(range_hi, range_lo);
  // Solid boards of 700 kg/m^3 make a chair too heavy; the posterior brings it into a chair's range.
  EXPECT_GT(plain->properties.object.mass_kg, range_hi);
  EXPECT_GE(r->properties.object.mass_kg, range_lo);
  EXPECT_LE(r->properties.object.mass_kg, range_hi);
  int by_kind = 0;
  for (const PartReport& p : r->properties.parts) {
    if (p.properties.structure_source != ValueSource::kKind) continue;
    ++by_kind;
    bool noted = false;
    for (const std::string& n : p.properties.notes) noted |= n.rfind("the kind's mass: ", 0) == 0;
    EXPECT_TRUE(noted) << "part " << p.part;
  }
  EXPECT_GT(by_kind, 0);
  EXPECT_GT(r->properties.mass_median_kg, 0.0);
  EXPECT_LE(r->properties.mass_p05_kg, r->properties.mass_median_kg);
  EXPECT_LE(r->properties.mass_median_kg, r->properties.mass_p95_kg);
  // report.json carries the interval and the kind's range.
  const nlohmann::json report = nlohmann::json::parse(report_json(r->properties, r->table));
  EXPECT_DOUBLE_EQ(report["object"]["mass_interval_kg"]["median"].get<double>(), r->properties.mass_median_kg);
  EXPECT_DOUBLE_EQ(report["object"]["kind_mass_range_kg"][1].get<double>(), range_hi);

  // MuJoCo weighs the exported body: the chosen structures' mass, centre of mass and inertia.
  if (!have_mujoco()) GTEST_SKIP() << "built without MuJoCo";
  const std::string out = dir + "/out";
  std::filesystem::remove_all(out);
  ASSERT_TRUE(write_pipeline_output(out, *r, o).ok());
  // ranges.json: the posterior's interval per part, to sample from.
  const nlohmann::json ranges = nlohmann::json::parse(test::read_file(out + "/ranges.json"));
  EXPECT_EQ(ranges["format"], "g2p-ranges");
  EXPECT_EQ(ranges["object_mass_kg"]["from"], "posterior");
  EXPECT_DOUBLE_EQ(ranges["object_mass_kg"]["min"].get<double>(), r->properties.mass_p05_kg);
  ASSERT_FALSE(ranges["parts"].empty());
  for (const nlohmann::json& p : ranges["parts"])
    EXPECT_LE(p["mass_kg"]["min"].get<double>(), p["mass_kg"]["max"].get<double>()) << p.dump();
  Result<EngineCheck> engine = check_in_mujoco(out + "/chair.xml");
  ASSERT_TRUE(engine.ok()) << engine.status().to_string();
  const MassProperties& m = r->properties.object;
  EXPECT_NEAR(engine->mass_kg, m.mass_kg, 1e-6 * m.mass_kg);
  EXPECT_LT((engine->center_of_mass - m.center_of_mass).norm(), 1e-4);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(engine->principal_moments[i], m.principal_moments()[i], 1e-4 * m.principal_moments().maxCoeff());
  // It stands: dropped on the floor, it comes to rest.
  EXPECT_TRUE(engine->finite);
  EXPECT_LT(engine->final_speed_m_s, 0.05);
}

// A car of boxes as an OBJ: a 4 x 1.8 x 1.1 m body on four 0.6 m wheels
// beside it, all of one dark material named "rubber" (as a generated car's
// dark paint reads).
std::string write_box_car(const std::string& dir) {
  std::filesystem::create_directories(dir);
  std::ofstream mtl(dir + "/car.mtl");
  mtl << "newmtl rubber\nKd 0.1 0.1 0.1\n";
  std::ofstream obj(dir + "/car.obj");
  obj << "mtllib car.mtl\nusemtl rubber\n";
  ObjBoxes box{obj};
  box(0.0, 0.0, 0.3, 4.0, 1.8, 1.4);  // body
  for (double x : {0.4, 3.0})
    for (double y : {-0.26, 1.81}) box(x, y, 0.0, x + 0.6, y + 0.25, 0.6);  // wheels
  return dir + "/car.obj";
}

TEST(KindPosterior, ACarBodyVotedRubberIsSheetMetalWithItsMachineryAndRestsOnItsWheels) {
  const std::string dir = test::scratch_dir("KindPosteriorCar");
  const std::string car = write_box_car(dir);
  PipelineOptions o;
  o.views.width = o.views.height = 192;
  o.completer = {"partition", {{"resolution", "48"}}};
  o.identifier = {"object", {}};
  o.object = "car";
  Result<PipelineResult> r = Pipeline(o).run_file(car);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  // The body (the largest part) is Metal now, the wheels still Rubber, and the notes say why.
  int body = -1;
  for (std::size_t i = 0; i < r->projection.parts.size(); ++i)
    if (body < 0 || r->projection.parts[i].area_m2 > r->projection.parts[static_cast<std::size_t>(body)].area_m2)
      body = static_cast<int>(i);
  ASSERT_GE(body, 0);
  EXPECT_EQ(r->projection.parts[static_cast<std::size_t>(body)].label, table().find("Metal"));
  for (std::size_t i = 0; i < r->projection.parts.size(); ++i)
    if (static_cast<int>(i) != body) EXPECT_EQ(r->projection.parts[i].label, table().find("Rubber")) << i;
  ASSERT_FALSE(r->kind_class_changes.empty());
  EXPECT_NE(r->kind_class_changes[0].find("Rubber -> Metal"), std::string::npos) << r->kind_class_changes[0];
  // A car's mass at 4 m, the machinery inside its hollow body.
  EXPECT_GE(r->properties.object.mass_kg, r->properties.kind_range_kg[0]);
  EXPECT_LE(r->properties.object.mass_kg, r->properties.kind_range_kg[1]);
  const PartReport& shell = r->properties.parts[static_cast<std::size_t>(body)];
  EXPECT_EQ(shell.properties.structure, Structure::kHollow);
  EXPECT_GT(shell.contents.mass_kg, 0.0);

  // Dropped in MuJoCo it comes to rest on its wheels, upright.
  if (!have_mujoco()) GTEST_SKIP() << "built without MuJoCo";
  const std::string out = dir + "/out";
  std::filesystem::remove_all(out);
  ASSERT_TRUE(write_pipeline_output(out, *r, o).ok());
  Result<EngineCheck> engine = check_in_mujoco(out + "/car.xml");
  ASSERT_TRUE(engine.ok()) << engine.status().to_string();
  EXPECT_NEAR(engine->mass_kg, r->properties.object.mass_kg, 1e-6 * r->properties.object.mass_kg);
  EXPECT_TRUE(engine->finite);
  EXPECT_LT(engine->final_speed_m_s, 0.05);
  EXPECT_NEAR(engine->resting_lowest_m, 0.0, 0.02);  // the wheels on the floor
  // Upright: the centre of mass ends as high above the floor as it sits above the wheels' bottoms.
  EXPECT_NEAR(engine->final_height_m, r->properties.object.center_of_mass.z(), 0.05);
}

}  // namespace
}  // namespace g2p
