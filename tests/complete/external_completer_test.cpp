// The `external` completer runs real commands; complete() falls back when they fail.
#include <gtest/gtest.h>

#include "complete/complete_fixtures.h"
#include "g2p/complete.h"
#include "support/gltf_builder.h"

namespace g2p {
namespace {

// The backend's own behaviour: no part kept as given, no volume check (both
// are complete()'s, tested in closed_parts_test.cpp).
const CompletionOptions kBackendOnly = [] {
  CompletionOptions o;
  o.keep_closed_parts = false;
  o.volume_tolerance = 0.0;
  return o;
}();

constexpr int kWood = static_cast<int>(PaperClass::kWood);

std::unique_ptr<Completer> external(const std::string& command, const std::string& timeout = "60") {
  Result<std::unique_ptr<Completer>> c = make_completer("external", {{"command", command}, {"timeout", timeout}});
  EXPECT_TRUE(c.ok()) << c.status().to_string();
  return c.ok() ? std::move(*c) : nullptr;
}

TEST(ExternalCompleter, ReadsBackAClosedMesh) {
  // The "tool" returns the whole object, which here is the part's closed box.
  const Mesh box = test::box_mesh({0, 0, 0}, {0.3f, 0.2f, 0.1f});
  const std::vector<Part> parts = test::single_part(box, kWood);
  auto c = external("cp {object} {output}");
  ASSERT_NE(c, nullptr);
  Result<Completion> r = complete({&box, &parts, nullptr}, *c, nullptr, kBackendOnly);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_EQ(r->parts.size(), 1u);
  EXPECT_TRUE(r->parts[0].ok);
  EXPECT_EQ(r->parts[0].backend, "external");
  EXPECT_NEAR(r->parts[0].checks.volume_m3, 0.006, 1e-7);
  EXPECT_EQ(r->parts[0].mesh.num_faces(), 12);
}

TEST(ExternalCompleter, FailuresFallBackToPartition) {
  // An open tube: echoing the open patch back fails the checks.
  Mesh tube;
  for (int ring = 0; ring < 2; ++ring)
    for (int i = 0; i < 16; ++i)
      tube.positions.emplace_back(0.05 * std::cos(2 * M_PI * i / 16), 0.05 * std::sin(2 * M_PI * i / 16), 0.2 * ring);
  for (int i = 0; i < 16; ++i) {
    tube.triangles.emplace_back(i, (i + 1) % 16, 16 + (i + 1) % 16);
    tube.triangles.emplace_back(i, 16 + (i + 1) % 16, 16 + i);
  }
  const std::vector<Part> parts = test::single_part(tube, kWood);
  auto fallback = std::move(*make_completer("partition", {{"resolution", "64"}}));
  const struct {
    std::string command, timeout, expect_in_notes;
  } cases[] = {
      {"cp {input} {output}", "60", "failed the checks"},
      {"exit 3 # {output}", "60", "status 3"},
      {"sleep 20; cp {input} {output}", "0.3", "killed"},
      {"true {output}", "60", "part_0_closed.obj"},  // no file written
  };
  for (const auto& k : cases) {
    SCOPED_TRACE(k.command);
    auto c = external(k.command, k.timeout);
    ASSERT_NE(c, nullptr);
    // (The sleeping command's note "killed" shows its timeout fired; a wall-clock
    // bound here failed under a loaded sanitizer build, where the partition
    // fallback alone took 53 s.)
    Result<Completion> r = complete({&tube, &parts, nullptr}, *c, fallback.get(), kBackendOnly);
    ASSERT_TRUE(r.ok()) << r.status().to_string();
    ASSERT_EQ(r->parts.size(), 1u);
    const CompletedPart& p = r->parts[0];
    EXPECT_TRUE(p.ok);
    EXPECT_EQ(p.backend, "partition");
    std::string notes;
    for (const auto& n : p.notes) notes += n + "\n";
    EXPECT_NE(notes.find(k.expect_in_notes), std::string::npos) << notes;
    EXPECT_NE(notes.find("fell back to 'partition'"), std::string::npos) << notes;
    // Without a fallback the failed part stays flagged.
    Result<Completion> alone = complete({&tube, &parts, nullptr}, *c, nullptr, kBackendOnly);
    ASSERT_TRUE(alone.ok());
    EXPECT_FALSE(alone->parts[0].ok);
  }
}

TEST(ExternalCompleter, NeedsACommandWithAnOutput) {
  EXPECT_FALSE(make_completer("external", {{"command", "holopart {input}"}}).ok());
  EXPECT_FALSE(make_completer("external", {{"timeout", "-1"}}).ok());
  EXPECT_FALSE(make_completer("external", {{"format", "fbx"}}).ok());
  auto c = std::move(*make_completer("external"));
  const Mesh box = test::box_mesh({0, 0, 0}, {1, 1, 1});
  const std::vector<Part> parts = test::single_part(box, kWood);
  Result<Completion> r = c->complete({&box, &parts, nullptr});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("no command"), std::string::npos);
}

}  // namespace
}  // namespace g2p
