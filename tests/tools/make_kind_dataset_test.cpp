// g2p_make_kind_dataset (tools/training/make_kind_dataset.cpp) on a small
// sweethome3d-style library the test writes: catalogue names to kinds (the
// matcher, the reviewed labels, none), the splits, the views the classifier
// sees, and the copies that look generated.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <vector>

#include "g2p/identify.h"
#include "g2p/io.h"
#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;
using test::quote;

// A textured-looking box (two materials) as OBJ and MTL.
void write_box(const std::string& dir, const std::string& name) {
  fs::create_directories(dir);
  std::ostringstream obj;
  obj << "mtllib " << name << ".mtl\n";
  for (int i = 0; i < 8; ++i)
    obj << "v " << (i & 1) * 0.6 << " " << ((i >> 1) & 1) * 0.4 << " " << ((i >> 2) & 1) << "\n";
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (int q = 0; q < 6; ++q) {
    obj << "usemtl " << (q < 3 ? "red" : "blue") << "\nf";
    for (int k : quads[q]) obj << " " << k + 1;
    obj << "\n";
  }
  test::write_file(dir + "/" + name + ".obj", obj.str());
  test::write_file(dir + "/" + name + ".mtl", "newmtl red\nKd 0.8 0.1 0.1\nnewmtl blue\nKd 0.1 0.2 0.8\n");
}

int run_tool(const std::string& args) {
  const std::string cmd = quote(G2P_TEST_MAKE_KIND_DATASET) + " " + args + " >/dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The rows of a CSV file whose cells hold no comma or quote (as this test's do).
std::vector<std::vector<std::string>> rows(const std::string& path) {
  std::vector<std::vector<std::string>> out;
  std::istringstream in(test::read_file(path));
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells(1);
    for (char c : line) {
      if (c == ',')
        cells.emplace_back();
      else
        cells.back().push_back(c);
    }
    out.push_back(cells);
  }
  return out;
}

}  // namespace

TEST(ToolMakeKindDataset, LabelsSplitsAndRendersAsTheClassifierSees) {
  const std::string dir = test::scratch_dir("ToolMakeKindDataset.library");
  fs::remove_all(dir);
  const std::string lib = dir + "/Lib";
  for (const char* m : {"chair", "lift", "gadget", "stool"}) write_box(lib + "/lib/" + m, m);
  // ISO 8859-1 as Java writes properties: "Chaise \xe9l\xe9gante" is
  // "Chaise élégante"; \u0020 an escaped space.
  test::write_file(lib + "/PluginFurnitureCatalog.properties",
                   "# a catalogue\n"
                   "id=Lib\n"
                   "name#1=Chair\ncategory#1=Living room\nmodel#1=/lib/chair/chair.obj\n"
                   "name#2=Fork\\u0020lift\ncategory#2=Misc\nmodel#2=/lib/lift/lift.obj\n"
                   "name#3=Gadget \xe9l\xe9gant\ncategory#3=Misc\nmodel#3=/lib/gadget/gadget.obj\n"
                   "name#4=Stool\ncategory#4=Kitchen\nmodel#4=/lib/stool/stool.obj\n");
  write_box(dir + "/Held/lib/chair", "chair");
  test::write_file(dir + "/Held/PluginFurnitureCatalog.properties", "name#1=Chair\nmodel#1=/lib/chair/chair.obj\n");
  test::write_file(dir + "/labels.json", R"({"labels": {"Fork lift": "forklift"}})");
  test::write_file(dir + "/val.json", R"({"models": {"Lib/lib/stool/stool.obj": {"name": "Stool"}}})");
  const std::string out = dir + "/ds";
  ASSERT_EQ(run_tool(quote(out) + " " + quote(lib) + " " + quote(dir + "/Held") + " --hold-out Held --labels " +
                     quote(dir + "/labels.json") + " --val " + quote(dir + "/val.json") + " --copies 2 --size 64"),
            0);

  std::map<std::string, std::vector<std::string>> model;  // key -> row
  const auto m = rows(out + "/models.csv");
  ASSERT_EQ(m.front(), (std::vector<std::string>{"model", "library", "split", "name", "category", "kind", "rule"}));
  for (std::size_t i = 1; i < m.size(); ++i) model[m[i][0]] = m[i];
  ASSERT_EQ(model.size(), 4u) << "the held-out library is not read";
  EXPECT_EQ(model["Lib/lib/chair/chair.obj"][5], "chair");
  EXPECT_EQ(model["Lib/lib/chair/chair.obj"][6], "name");
  EXPECT_EQ(model["Lib/lib/lift/lift.obj"][3], "Fork lift");
  EXPECT_EQ(model["Lib/lib/lift/lift.obj"][5], "forklift");
  EXPECT_EQ(model["Lib/lib/lift/lift.obj"][6], "hand (name)");
  EXPECT_EQ(model["Lib/lib/gadget/gadget.obj"][3], "Gadget \xc3\xa9l\xc3\xa9gant");  // as UTF-8
  EXPECT_EQ(model["Lib/lib/gadget/gadget.obj"][5], "");
  EXPECT_EQ(model["Lib/lib/stool/stool.obj"][2], "val");

  // 8 views a copy: two copies of each training model with a kind, one of the
  // validation model, none of the model of no kind.
  std::map<std::string, int> views;
  std::map<std::string, std::string> first_image;  // "key copy" -> its first view
  const auto v = rows(out + "/views.csv");
  ASSERT_EQ(v.front(), (std::vector<std::string>{"image", "model", "split", "copy", "view"}));
  for (std::size_t i = 1; i < v.size(); ++i) {
    ++views[v[i][1]];
    first_image.emplace(v[i][1] + " " + v[i][3], v[i][0]);
  }
  EXPECT_EQ(views["Lib/lib/chair/chair.obj"], 16);
  EXPECT_EQ(views["Lib/lib/lift/lift.obj"], 16);
  EXPECT_EQ(views["Lib/lib/stool/stool.obj"], 8);
  EXPECT_EQ(views.count("Lib/lib/gadget/gadget.obj"), 0u);

  // The crops: size x size, the object framed on grey 128 (corners), and
  // the second copy looks otherwise than the first.
  Result<ImageU8> plain = read_image(out + "/images/" + first_image["Lib/lib/chair/chair.obj 0"]);
  Result<ImageU8> generated = read_image(out + "/images/" + first_image["Lib/lib/chair/chair.obj 1"]);
  ASSERT_TRUE(plain.ok() && generated.ok());
  EXPECT_EQ(plain->width(), 64);
  EXPECT_EQ(plain->height(), 64);
  ASSERT_EQ(plain->channels(), 4);  // read_image gives RGBA; the file is opaque
  for (int c = 0; c < 3; ++c) EXPECT_EQ(plain->at(0, 0, c), 128);
  EXPECT_EQ(plain->at(0, 0, 3), 255);
  long differ = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) differ += plain->at(x, y, 0) != generated->at(x, y, 0);
  EXPECT_GT(differ, 64 * 64 / 10);

  // Each rendered copy's shape cues, after its lumps and turn; --cues-only
  // measures the same copies without rendering them.
  const auto c = rows(out + "/cues.csv");
  std::vector<std::string> header = {"model", "copy"};
  for (const std::string& name : shape_cue_names()) header.push_back(name);
  ASSERT_EQ(c.front(), header);
  std::map<std::string, int> copies;
  for (std::size_t i = 1; i < c.size(); ++i) {
    ASSERT_EQ(c[i].size(), header.size());
    ++copies[c[i][0]];
  }
  EXPECT_EQ(copies["Lib/lib/chair/chair.obj"], 2);
  EXPECT_EQ(copies["Lib/lib/stool/stool.obj"], 1);
  EXPECT_EQ(copies.count("Lib/lib/gadget/gadget.obj"), 0u);
  const std::string measured = dir + "/measured";
  ASSERT_EQ(run_tool(quote(measured) + " " + quote(lib) + " --labels " + quote(dir + "/labels.json") + " --val " +
                     quote(dir + "/val.json") + " --copies 2 --cues-only"),
            0);
  EXPECT_EQ(rows(measured + "/cues.csv"), c);
  EXPECT_FALSE(std::filesystem::exists(measured + "/images"));
  EXPECT_FALSE(std::filesystem::exists(measured + "/views.csv"));

  // An existing folder is refused, nothing written into it.
  EXPECT_EQ(run_tool(quote(out) + " " + quote(lib)), 2);
}

}  // namespace g2p
