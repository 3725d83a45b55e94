// g2p_make_dataset (tools/training/make_dataset.cpp) on a small library the
// test writes: three boxes whose materials are named by the lexicon ("oak"),
// by a per-model override ("Material.001") and by nothing ("Material.002").
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <vector>

#include "augment.h"
#include "g2p/io.h"
#include "g2p/materials.h"
#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;
using test::quote;

// An OBJ of three unit boxes along x, one per material, and its MTL.
void write_boxes(const std::string& dir, const std::string& name) {
  fs::create_directories(dir);
  std::ostringstream obj;
  obj << "mtllib " << name << ".mtl\n";
  const char* materials[3] = {"oak", "Material.001", "Material.002"};
  for (int b = 0; b < 3; ++b) {
    const double x0 = 1.2 * b;
    for (int i = 0; i < 8; ++i) obj << "v " << x0 + (i & 1) << " " << ((i >> 1) & 1) << " " << ((i >> 2) & 1) << "\n";
    obj << "usemtl " << materials[b] << "\n";
    const int o = 8 * b + 1;  // OBJ indices start at 1
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads)
      obj << "f " << o + q[0] << " " << o + q[1] << " " << o + q[2] << " " << o + q[3] << "\n";
  }
  test::write_file(dir + "/" + name + ".obj", obj.str());
  test::write_file(dir + "/" + name + ".mtl",
                   "newmtl oak\nKd 0.6 0.4 0.2\nnewmtl Material.001\nKd 0.7 0.7 0.7\nnewmtl Material.002\nKd 0.2 0.3 "
                   "0.8\n");
}

int run_make_dataset(const std::string& args) {
  const std::string cmd = quote(G2P_TEST_MAKE_DATASET) + " " + args + " >/dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(ToolMakeDataset, LabelsRendersAndReportsEveryMaterial) {
  const std::string dir = test::scratch_dir("ToolMakeDataset.library");
  fs::remove_all(dir);
  write_boxes(dir + "/TrainLib/boxes", "boxes");
  write_boxes(dir + "/HeldOut/boxes", "boxes");
  test::write_file(dir + "/overrides.json",
                   R"({"names": {}, "models": {"TrainLib/boxes/boxes.obj": {"Material.001": "Metal"}}})");
  const std::string out = dir + "/dataset";
  ASSERT_EQ(
      run_make_dataset(quote(out) + " " + quote(dir + "/TrainLib") + " " + quote(dir + "/HeldOut") +
                       " --test HeldOut --views 3 --size 48 --normals --overrides " + quote(dir + "/overrides.json")),
      0);

  // Labels: the lexicon for "oak", the override for Material.001 (only in the
  // model it names), nothing for Material.002.
  const MaterialTable& table = MaterialTable::paper_default();
  const nlohmann::json labels = nlohmann::json::parse(test::read_file(out + "/labels.json"))["models"];
  ASSERT_TRUE(labels.contains("TrainLib/boxes/boxes.obj")) << labels.dump();
  EXPECT_EQ(labels["TrainLib/boxes/boxes.obj"]["split"], "train");
  EXPECT_EQ(labels["HeldOut/boxes/boxes.obj"]["split"], "test");
  std::map<std::string, std::string> rule, label;  // "library/name" -> ...
  {
    std::istringstream csv(test::read_file(out + "/materials.csv"));
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line, "library,model,split,material,name,texture,r,g,b,area_share,rule,class");
    while (std::getline(csv, line)) {
      std::vector<std::string> f;
      std::stringstream s(line);
      for (std::string field; std::getline(s, field, ',');) f.push_back(field);
      if (line.back() == ',') f.emplace_back();
      ASSERT_EQ(f.size(), 12u) << line;
      rule[f[0] + "/" + f[4]] = f[10];
      label[f[0] + "/" + f[4]] = f[11];
      EXPECT_NEAR(std::stod(f[9]), 1.0 / 3.0, 1e-6) << line;  // three equal boxes
    }
  }
  EXPECT_EQ(rule["TrainLib/oak"], "lexicon");
  EXPECT_EQ(label["TrainLib/oak"], "Wood");
  EXPECT_EQ(rule["TrainLib/Material.001"], "override (model)");
  EXPECT_EQ(label["TrainLib/Material.001"], "Metal");
  EXPECT_EQ(rule["HeldOut/Material.001"], "no material word");
  EXPECT_EQ(label["HeldOut/Material.001"], "");
  EXPECT_EQ(rule["TrainLib/Material.002"], "no material word");

  // Per class and split: each box is 12 triangles.
  const nlohmann::json stats = nlohmann::json::parse(test::read_file(out + "/stats.json"));
  EXPECT_EQ(stats["splits"]["train"]["classes"]["Wood"]["faces"], 12);
  EXPECT_EQ(stats["splits"]["train"]["classes"]["Metal"]["faces"], 12);
  EXPECT_EQ(stats["splits"]["test"]["classes"]["Wood"]["faces"], 12);
  EXPECT_EQ(stats["splits"]["test"]["classes"]["Metal"]["faces"], 0);

  // Every manifest row has its image, label map and normals; label pixels are
  // Wood, Metal (train only) or 255; normals decode to unit vectors on labelled pixels.
  std::istringstream manifest(test::read_file(out + "/manifest.csv"));
  std::string row;
  std::getline(manifest, row);
  int rows = 0, metal_pixels = 0;
  while (std::getline(manifest, row)) {
    ++rows;
    const std::string image = row.substr(0, row.find(','));
    const bool train = row.find(",train,") != std::string::npos;
    Result<ImageU8> rgb = read_image(out + "/images/" + image), lab = read_image(out + "/labels/" + image),
                    nor = read_image(out + "/normals/" + image);
    ASSERT_TRUE(rgb.ok() && lab.ok() && nor.ok()) << image;
    ASSERT_EQ(lab->width(), 48);
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 48; ++x) {
        const int l = lab->at(x, y);
        ASSERT_TRUE(l == 255 || l == table.find("Wood") || (train && l == table.find("Metal"))) << image << " " << l;
        metal_pixels += l == table.find("Metal");
        if (l == 255) continue;
        double norm2 = 0;
        for (int c = 0; c < 3; ++c) norm2 += std::pow(nor->at(x, y, c) / 127.5 - 1.0, 2);
        ASSERT_NEAR(std::sqrt(norm2), 1.0, 0.02) << image << " pixel " << x << "," << y;
      }
  }
  EXPECT_EQ(rows, 6);  // 3 views of each model
  EXPECT_GT(metal_pixels, 0);

  // An existing folder is refused and left as it was.
  const std::string before = test::read_file(out + "/labels.json");
  EXPECT_EQ(run_make_dataset(quote(out) + " " + quote(dir + "/TrainLib")), 2);
  EXPECT_EQ(test::read_file(out + "/labels.json"), before);
}

// --geometry-noise: the same views, the normals bumpy, the silhouettes (and
// so the labels) nearly unchanged.
TEST(ToolMakeDataset, GeometryNoiseBendsNormalsAndKeepsTheViews) {
  const std::string dir = test::scratch_dir("ToolMakeDataset.noise");
  fs::remove_all(dir);
  write_boxes(dir + "/Lib/boxes", "boxes");
  double normal_change = 0;
  long labelled = 0, label_changes = 0, pixels = 0;
  std::map<std::string, ImageU8> clean_normals, clean_labels;
  for (int noisy = 0; noisy < 2; ++noisy) {
    const std::string out = dir + "/out" + std::to_string(noisy);
    ASSERT_EQ(run_make_dataset(quote(out) + " " + quote(dir + "/Lib") + " --test None --views 4 --size 96 --normals " +
                               "--geometry-noise " + std::to_string(noisy)),
              0);
    for (const auto& entry : fs::directory_iterator(out + "/labels")) {
      const std::string name = entry.path().filename().string();
      Result<ImageU8> label = read_image(entry.path().string());
      Result<ImageU8> normal = read_image(out + "/normals/" + name);
      ASSERT_TRUE(label.ok() && normal.ok()) << name;
      if (!noisy) {
        for (std::size_t i = 0; i < label->size(); ++i) labelled += label->data()[i] != 255;
        clean_labels[name] = *label;
        clean_normals[name] = *normal;
        continue;
      }
      ASSERT_TRUE(clean_labels.count(name)) << name;
      const ImageU8& l0 = clean_labels[name];
      const ImageU8& n0 = clean_normals[name];
      for (int y = 0; y < label->height(); ++y)
        for (int x = 0; x < label->width(); ++x) {
          label_changes += label->at(x, y) != l0.at(x, y);
          if (label->at(x, y) == 255 || l0.at(x, y) == 255) continue;
          ++pixels;
          for (int c = 0; c < 3; ++c) normal_change += std::abs(normal->at(x, y, c) - n0.at(x, y, c)) / 127.5;
        }
    }
  }
  ASSERT_GT(pixels, 1000);
  std::printf("noise: mean |dn| %.3f per component, labels changed on %.2f %% of pixels\n",
              normal_change / (3.0 * pixels), 100.0 * label_changes / labelled);
  EXPECT_GT(normal_change / (3.0 * pixels), 0.02);  // bumpy shading (0 without noise)
  EXPECT_LT(label_changes, 0.05 * labelled);        // the same views; silhouettes move by a pixel at most
}

// The noise itself: vertices at one position (a seam) move together, others
// independently, by the asked standard deviation; normals stay unit length.
TEST(GeometryNoise, CoincidentVerticesMoveTogether) {
  Mesh mesh;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3f p(u(rng), u(rng), u(rng));
    mesh.positions.push_back(p);
    mesh.positions.push_back(p);  // its twin across a seam
    mesh.normals.push_back(Eigen::Vector3f::UnitZ());
    mesh.normals.push_back(Eigen::Vector3f::UnitX());
  }
  mesh.positions.push_back(Eigen::Vector3f::Zero());  // bounds from (0,0,0) to (1,1,1)
  mesh.positions.push_back(Eigen::Vector3f::Ones());
  const Mesh before = mesh;
  const double diagonal = bounds(mesh).diagonal().norm();
  training::add_geometry_noise(mesh, 0.002, 0.15, 42);
  double sum2 = 0;
  for (int i = 0; i < 4000; i += 2) {
    ASSERT_EQ(mesh.positions[i], mesh.positions[i + 1]) << "twins " << i << " split";
    const Eigen::Vector3f d = mesh.positions[i] - before.positions[i];
    sum2 += d.squaredNorm();
    EXPECT_NEAR(mesh.normals[i].norm(), 1.f, 1e-5f);
    EXPECT_NE(mesh.normals[i], before.normals[i]);
  }
  EXPECT_NE(mesh.positions[0] - before.positions[0], mesh.positions[2] - before.positions[2]);
  const double sigma = std::sqrt(sum2 / (3 * 2000)) / diagonal;
  EXPECT_NEAR(sigma, 0.002, 0.0002) << "per-axis standard deviation over the diagonal";
  Mesh again = before;  // the same seed, the same noise
  training::add_geometry_noise(again, 0.002, 0.15, 42);
  EXPECT_EQ(again.positions, mesh.positions);
}

// --random-lights: the same views and labels, other shading.
TEST(ToolMakeDataset, RandomLightsChangeTheShadingNotTheViews) {
  const std::string dir = test::scratch_dir("ToolMakeDataset.lights");
  fs::remove_all(dir);
  write_boxes(dir + "/Lib/boxes", "boxes");
  for (const char* share : {"0", "1"})
    ASSERT_EQ(run_make_dataset(quote(dir + "/out" + share) + " " + quote(dir + "/Lib") +
                               " --test None --views 4 --size 64 --geometry-noise 0 --random-lights " + share),
              0);
  int images = 0;
  double change = 0;
  long pixels = 0;
  for (const auto& entry : fs::directory_iterator(dir + "/out0/images")) {
    const std::string name = entry.path().filename().string();
    EXPECT_EQ(test::read_file(dir + "/out0/labels/" + name), test::read_file(dir + "/out1/labels/" + name)) << name;
    Result<ImageU8> a = read_image(entry.path().string()), b = read_image(dir + "/out1/images/" + name);
    Result<ImageU8> label = read_image(dir + "/out0/labels/" + name);
    ASSERT_TRUE(a.ok() && b.ok() && label.ok()) << name;
    for (int y = 0; y < a->height(); ++y)
      for (int x = 0; x < a->width(); ++x) {
        if (label->at(x, y) == 255) continue;
        ++pixels;
        for (int c = 0; c < 3; ++c) change += std::abs(a->at(x, y, c) - b->at(x, y, c));
      }
    ++images;
  }
  EXPECT_EQ(images, 4);
  ASSERT_GT(pixels, 500);
  EXPECT_GT(change / (3.0 * pixels), 3.0) << "mean change per channel, 8-bit";
}

TEST(RandomLights, JitteredStudioLightsAreValidAndReproducible) {
  std::mt19937_64 a(7), b(7);
  const std::vector<CameraLight> first = training::jittered_studio_lights(a);
  const std::vector<CameraLight> again = training::jittered_studio_lights(b);
  const std::vector<CameraLight> studio = studio_lights();
  ASSERT_EQ(first.size(), studio.size());
  for (std::size_t i = 0; i < first.size(); ++i) {
    EXPECT_NEAR(first[i].direction.norm(), 1.f, 1e-5f);
    EXPECT_GE(first[i].irradiance, 0.5f * studio[i].irradiance - 1e-6f);
    EXPECT_LE(first[i].irradiance, 1.5f * studio[i].irradiance + 1e-6f);
    EXPECT_EQ(first[i].direction, again[i].direction);
    EXPECT_NE(first[i].direction, studio[i].direction);
  }
}

TEST(FlatTexture, MeanLinearColourWeighsByAlpha) {
  auto image = std::make_shared<ImageU8>(2, 1, 4, 0);
  image->at(0, 0, 0) = 255, image->at(0, 0, 3) = 255;  // opaque red
  image->at(1, 0, 2) = 255, image->at(1, 0, 3) = 0;    // transparent blue: no weight
  Texture t;
  t.image = image;
  EXPECT_TRUE(training::mean_linear_colour(t).isApprox(Eigen::Vector3f(1, 0, 0)));
  image->at(1, 0, 3) = 255;  // both opaque: half of each, linear
  EXPECT_TRUE(training::mean_linear_colour(t).isApprox(Eigen::Vector3f(0.5f, 0, 0.5f)));
  image->at(0, 0, 0) = 188;  // sRGB 188 is about 0.5 linear
  EXPECT_NEAR(training::mean_linear_colour(t)[0], 0.25f, 0.005f);
  EXPECT_TRUE(training::mean_linear_colour(Texture{}).isApprox(Eigen::Vector3f::Ones()));
}

// Vertex colours: each vertex takes the texel at its UV (nearest, linear),
// times any colour it had; vertices of an untextured material stay white.
TEST(VertexColours, EachVertexTakesTheTexelAtItsUv) {
  auto image = std::make_shared<ImageU8>(2, 1, 4, 255);
  image->at(0, 0, 1) = 0, image->at(0, 0, 2) = 0;  // red | white
  Model model;
  model.materials.resize(2);
  model.materials[0].base_color_texture.image = image;
  Mesh& mesh = model.mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {3, 0, 0}, {2, 1, 0}};
  mesh.uvs = {{0.25f, 0.5f}, {0.75f, 0.5f}, {1.25f, 0.5f}, {0.25f, 0.5f}, {0.25f, 0.5f}, {0.25f, 0.5f}};
  mesh.triangles = {{0, 1, 2}, {3, 4, 5}};
  mesh.face_source = {{0, 0, 0}, {0, 1, 1}};
  training::texture_to_vertex_colours(model, mesh);
  ASSERT_EQ(mesh.colors.size(), 6u);
  EXPECT_TRUE(mesh.colors[0].isApprox(Eigen::Vector4f(1, 0, 0, 1)));
  EXPECT_TRUE(mesh.colors[1].isApprox(Eigen::Vector4f(1, 1, 1, 1)));
  EXPECT_TRUE(mesh.colors[2].isApprox(Eigen::Vector4f(1, 0, 0, 1))) << "u 1.25 repeats to 0.25";
  for (int v = 3; v < 6; ++v) EXPECT_TRUE(mesh.colors[v].isApprox(Eigen::Vector4f::Ones())) << "untextured " << v;
}

// Baked light: under a roof a floor gets less light than the roof's top,
// and a box is brighter on the side of the key light than on the far side.
TEST(BakedLighting, ShadowsDarkenWhatIsCoveredAndTheKeySideIsBrightest) {
  const auto quad = [](Mesh& m, double half, double z, int n) {  // an n x n grid facing +Z
    const int base = m.num_vertices();
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        m.positions.emplace_back(-half + 2 * half * i / n, -half + 2 * half * j / n, z);
        m.normals.emplace_back(0.f, 0.f, 1.f);
      }
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int a = base + j * (n + 1) + i;
        m.triangles.emplace_back(a, a + 1, a + n + 2);
        m.triangles.emplace_back(a, a + n + 2, a + n + 1);
      }
  };
  Model covered;
  quad(covered.mesh, 1.0, 1.0, 4);  // the roof: 25 vertices
  quad(covered.mesh, 0.3, 0.0, 4);  // the floor under it
  Mesh lit = covered.mesh;
  ASSERT_TRUE(training::bake_lighting(covered, lit, Eigen::Vector3f::UnitZ()).ok());
  ASSERT_EQ(lit.colors.size(), lit.positions.size());
  double roof = 0, floor = 0;
  for (int v = 0; v < 25; ++v) roof += lit.colors[v].x() / 25;
  for (int v = 25; v < 50; ++v) floor += lit.colors[v].x() / 25;
  EXPECT_GT(roof, 0.9) << "the roof's top sees the whole sky";
  EXPECT_LT(floor, 0.5 * roof) << "the roof hides the sky above 45 degrees from the floor";
  EXPECT_GE(floor, 0.12 - 1e-6) << "the floor of the baked light";
  for (const Eigen::Vector4f& c : lit.colors) EXPECT_EQ(c.w(), 1.f) << "alpha untouched";

  Model box;  // a unit cube, four vertices per face with its normal
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {-1, 1}) {
      const int base = box.mesh.num_vertices();
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      n[axis] = static_cast<float>(sign);
      const Eigen::Vector3f u = Eigen::Vector3f::Unit((axis + 1) % 3), w = Eigen::Vector3f::Unit((axis + 2) % 3);
      for (int k = 0; k < 4; ++k) {
        box.mesh.positions.push_back(0.5f * n + 0.5f * ((k & 1) ? u : -u) + 0.5f * ((k & 2) ? w : -w));
        box.mesh.normals.push_back(n);
      }
      box.mesh.triangles.emplace_back(base, base + 1, base + 3);
      box.mesh.triangles.emplace_back(base, base + 3, base + 2);
    }
  Mesh boxed = box.mesh;
  ASSERT_TRUE(training::bake_lighting(box, boxed, Eigen::Vector3f::UnitX(), 0.3f, 0.f).ok());
  const float plus_x = boxed.colors[4].x(), minus_x = boxed.colors[0].x(), plus_y = boxed.colors[12].x();
  EXPECT_GT(plus_x, minus_x + 0.3f) << "the key's side against the far side";
  EXPECT_GT(plus_x, plus_y) << "the key's side against a side it grazes";
  EXPECT_NEAR(boxed.colors[5].x(), plus_x, 1e-6f) << "one face, one light";
}

// --flat-textures: a striped red and blue texture becomes its mean colour
// (purple, no stripes left; dropping the texture would leave the white of
// Kd); without it both stripes show.
TEST(ToolMakeDataset, FlatTexturesKeepTheMeanColourAndLoseThePattern) {
  const std::string dir = test::scratch_dir("ToolMakeDataset.flat");
  fs::remove_all(dir);
  const std::string model = dir + "/Lib/box";
  fs::create_directories(model);
  ImageU8 stripes(64, 64, 3, 0);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) stripes.at(x, y, (x / 8) % 2 == 0 ? 0 : 2) = 255;
  ASSERT_TRUE(write_image(model + "/stripes.png", stripes).ok());
  std::ostringstream obj;
  obj << "mtllib box.mtl\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
  for (int i = 0; i < 8; ++i) obj << "v " << (i & 1) << " " << ((i >> 1) & 1) << " " << ((i >> 2) & 1) << "\n";
  obj << "usemtl oak\n";
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads)
    obj << "f " << q[0] + 1 << "/1 " << q[1] + 1 << "/2 " << q[2] + 1 << "/3 " << q[3] + 1 << "/4\n";
  test::write_file(model + "/box.obj", obj.str());
  test::write_file(model + "/box.mtl", "newmtl oak\nKd 1 1 1\nmap_Kd stripes.png\n");

  for (const char* flat : {"0", "1"}) {
    const std::string out = dir + "/out" + flat;
    ASSERT_EQ(run_make_dataset(quote(out) + " " + quote(dir + "/Lib") + " --test None --views 4 --size 64 --white 0 " +
                               "--pbr-defaults 0 --flat-textures " + flat),
              0);
    int pixels = 0, red = 0, blue = 0, even = 0;
    for (const auto& entry : fs::directory_iterator(out + "/images")) {
      Result<ImageU8> rgb = read_image(entry.path().string());
      Result<ImageU8> label = read_image(out + "/labels/" + entry.path().filename().string());
      ASSERT_TRUE(rgb.ok() && label.ok());
      for (int y = 0; y < rgb->height(); ++y)
        for (int x = 0; x < rgb->width(); ++x) {
          if (label->at(x, y, 0) == 255) continue;
          const int r = rgb->at(x, y, 0), g = rgb->at(x, y, 1), b = rgb->at(x, y, 2);
          ++pixels;
          red += r > 2 * b + 10;
          blue += b > 2 * r + 10;
          even += std::abs(r - b) <= 0.15 * std::max(r, b) + 4 && g < 0.6 * std::max(r, b);  // purple, not grey
        }
    }
    ASSERT_GT(pixels, 500) << flat;
    if (flat[0] == '0') {
      EXPECT_GT(red, pixels / 5) << "stripes expected";
      EXPECT_GT(blue, pixels / 5) << "stripes expected";
    } else {
      EXPECT_GT(even, 0.97 * pixels) << "one mean colour expected: red " << red << ", blue " << blue;
    }
  }
}

}  // namespace
}  // namespace g2p
