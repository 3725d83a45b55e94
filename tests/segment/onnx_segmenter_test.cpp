// The `onnx` backend on a tiny network the test writes with python3-onnx
// (make_tiny_onnx.py): each pixel's class is its strongest colour channel.
#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "g2p/io.h"
#include "g2p/segment.h"
#include "segment/segment_fixtures.h"
#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

std::string make_model_dir() {
  const std::string dir = test::scratch_dir("OnnxSegmenter.model");
  const std::string cmd =
      "/usr/bin/python3 " + test::quote(test::source_path("tests/segment/make_tiny_onnx.py")) + " " + test::quote(dir);
  EXPECT_EQ(std::system(cmd.c_str()), 0) << "writing the ONNX model needs Debian's python3-onnx "
                                            "(scripts/install-deps.sh installs it)";
  return dir;
}

// Red, green and blue boxes, matte and dielectric.
Model rgb_boxes() {
  return test::boxes({{"a", {1, 0, 0, 1}, 0.f, 1.f}, {"b", {0, 1, 0, 1}, 0.f, 1.f}, {"c", {0, 0, 1, 1}, 0.f, 1.f}},
                     "OnnxSegmenter.boxes");
}

TEST(OnnxSegmenter, RunsTheNetworkAndMapsItsClasses) {
  const std::string dir = make_model_dir();
  const Model model = rgb_boxes();
  const std::vector<View> views = test::render(model, 2, 96);
  const MaterialTable& table = MaterialTable::paper_default();
  for (const char* order : {"rgb", "bgr"}) {
    Result<std::unique_ptr<Segmenter>> s =
        make_segmenter("onnx", {{"model_card", dir + "/card_" + std::string(order) + ".json"}});
    ASSERT_TRUE(s.ok()) << s.status().to_string();
    ASSERT_TRUE((*s)->set_model(model, table).ok());
    std::vector<LabelMap> maps(views.size());
    for (std::size_t i = 0; i < views.size(); ++i) ASSERT_TRUE((*s)->segment_into(views[i], maps[i]).ok());
    const bool bgr = std::string(order) == "bgr";
    // Channel 0 of the network's input is red (RGB card) or blue (BGR card); its class is Wood.
    EXPECT_EQ(test::majority_label(model, views, maps, 0), table.find(bgr ? "Glass" : "Wood")) << order;
    EXPECT_EQ(test::majority_label(model, views, maps, 1), table.find("Metal")) << order;
    EXPECT_EQ(test::majority_label(model, views, maps, 2), table.find(bgr ? "Wood" : "Glass")) << order;
    // Background stays unknown; probabilities cover the three mapped classes only.
    for (std::size_t i = 0; i < views[0].face_id.size(); ++i) {
      if (views[0].face_id.data()[i] < 0) {
        ASSERT_EQ(maps[0].labels.data()[i], kUnknownLabel);
      } else {
        const float* p = maps[0].probabilities.data() + 12 * i;
        ASSERT_NEAR(p[table.find("Wood")] + p[table.find("Metal")] + p[table.find("Glass")], 1.f, 1e-5f);
      }
    }
  }
}

// A card whose input.channels is ["rgb", "normal"]: the network sees the
// camera-space normal (make_tiny_onnx.py: facing right -> Wood, left -> Metal,
// neither or no normal buffer -> Glass).
TEST(OnnxSegmenter, FeedsCameraSpaceNormalsWhenTheCardAsksForThem) {
  const std::string dir = make_model_dir();
  const Model model = rgb_boxes();
  const std::vector<View> views = test::render(model, 3, 96);
  const MaterialTable& table = MaterialTable::paper_default();
  Result<std::unique_ptr<Segmenter>> s = make_segmenter("onnx", {{"model_card", dir + "/card_normals.json"}});
  ASSERT_TRUE(s.ok()) << s.status().to_string();
  ASSERT_TRUE((*s)->set_model(model, table).ok());
  int right = 0, left = 0;
  for (const View& view : views) {
    ASSERT_EQ(view.normal.channels(), 3);
    Result<LabelMap> map = (*s)->segment(view);
    ASSERT_TRUE(map.ok()) << map.status().to_string();
    const Eigen::Matrix3d to_camera = view.camera.rotation.transpose();
    // Pixels well inside a face that turns clearly right or left; the network
    // sees the view at 32 px, so edges blur and are skipped.
    for (int y = 2; y + 2 < 96; ++y)
      for (int x = 2; x + 2 < 96; ++x) {
        const int f = view.face_id.at(x, y);
        bool interior = f >= 0;
        for (int dy = -2; dy <= 2 && interior; ++dy)
          for (int dx = -2; dx <= 2 && interior; ++dx) interior = view.face_id.at(x + dx, y + dy) == f;
        if (!interior) continue;
        const Eigen::Vector3d n =
            to_camera * Eigen::Vector3d(view.normal.at(x, y, 0), view.normal.at(x, y, 1), view.normal.at(x, y, 2));
        if (n.x() > 0.4) {
          EXPECT_EQ(map->labels.at(x, y), table.find("Wood")) << "pixel " << x << "," << y;
          ++right;
        } else if (n.x() < -0.4) {
          EXPECT_EQ(map->labels.at(x, y), table.find("Metal")) << "pixel " << x << "," << y;
          ++left;
        }
      }
  }
  EXPECT_GT(right, 100);
  EXPECT_GT(left, 100);
  // A view rendered without geometry buffers: the normals are zero, and the
  // network's answer is its bias (Glass) on every object pixel.
  RenderOptions no_geometry;
  no_geometry.geometry_buffers = false;
  Result<std::unique_ptr<Renderer>> renderer = renderer_registry().create("embree");
  ASSERT_TRUE(renderer.ok());
  ASSERT_TRUE((*renderer)->set_model(model).ok());
  Result<View> bare = (*renderer)->render(views[0].camera, no_geometry);
  ASSERT_TRUE(bare.ok());
  ASSERT_TRUE(bare->normal.empty());
  Result<LabelMap> map = (*s)->segment(*bare);
  ASSERT_TRUE(map.ok()) << map.status().to_string();
  int object = 0;
  for (std::size_t i = 0; i < bare->face_id.size(); ++i) {
    if (bare->face_id.data()[i] < 0) continue;
    ++object;
    ASSERT_EQ(map->labels.data()[i], table.find("Glass"));
  }
  EXPECT_GT(object, 500);
}

// A card that takes normals only needs no RGB image: a view rendered
// without shading is segmented as the view with it, and a colour-only card
// refuses that view, naming what it lacks; so does the normals-only card a
// view without normals.
TEST(OnnxSegmenter, ANormalsOnlyCardNeedsNoShading) {
  const std::string dir = make_model_dir();
  const Model model = rgb_boxes();
  const MaterialTable& table = MaterialTable::paper_default();
  Result<std::unique_ptr<Segmenter>> s = make_segmenter("onnx", {{"model_card", dir + "/card_normals_only.json"}});
  ASSERT_TRUE(s.ok()) << s.status().to_string();
  ASSERT_TRUE((*s)->set_model(model, table).ok());
  Result<std::unique_ptr<Renderer>> renderer = renderer_registry().create("embree");
  ASSERT_TRUE(renderer.ok() && (*renderer)->set_model(model).ok());
  const View shaded = test::render(model, 1, 96)[0];
  RenderOptions unshaded_options;
  unshaded_options.shade = false;
  Result<View> unshaded = (*renderer)->render(shaded.camera, unshaded_options);
  ASSERT_TRUE(unshaded.ok());
  ASSERT_TRUE(unshaded->rgb.empty());
  Result<LabelMap> with = (*s)->segment(shaded), without = (*s)->segment(*unshaded);
  ASSERT_TRUE(with.ok() && without.ok()) << without.status().to_string();
  int wood = 0, metal = 0;
  for (std::size_t i = 0; i < with->labels.size(); ++i) {
    ASSERT_EQ(without->labels.data()[i], with->labels.data()[i]);
    wood += with->labels.data()[i] == table.find("Wood");
    metal += with->labels.data()[i] == table.find("Metal");
  }
  EXPECT_GT(wood + metal, 500);  // the normals decide, as in the rgb+normal network
  Result<std::unique_ptr<Segmenter>> colour = make_segmenter("onnx", {{"model_card", dir + "/card_rgb.json"}});
  ASSERT_TRUE(colour.ok()) << colour.status().to_string();
  ASSERT_TRUE((*colour)->set_model(model, table).ok());
  Result<LabelMap> refused = (*colour)->segment(*unshaded);
  EXPECT_EQ(refused.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(refused.status().message().find("RGB image"), std::string::npos) << refused.status().to_string();
  // Neither shading nor geometry buffers: the normals-only card has nothing to read.
  RenderOptions nothing = unshaded_options;
  nothing.geometry_buffers = false;
  Result<View> bare = (*renderer)->render(shaded.camera, nothing);
  ASSERT_TRUE(bare.ok());
  Result<LabelMap> blind = (*s)->segment(*bare);
  EXPECT_EQ(blind.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(blind.status().message().find("normals only"), std::string::npos) << blind.status().to_string();
}

// flip=on: the network also sees the view mirrored (normals with it) and the
// mirrored pass's output is mirrored back before the two are averaged.
TEST(OnnxSegmenter, FlipAveragesTheMirroredView) {
  const std::string dir = make_model_dir();
  const Model model = rgb_boxes();
  const std::vector<View> views = test::render(model, 3, 96);
  const MaterialTable& table = MaterialTable::paper_default();
  auto segment = [&](const BackendSettings& settings, const View& view) {
    Result<std::unique_ptr<Segmenter>> s = make_segmenter(settings.count("names") ? "learned" : "onnx", settings);
    EXPECT_TRUE(s.ok()) << s.status().to_string();
    if (!s.ok() || !(*s)->set_model(model, table).ok()) return LabelMap{};
    Result<LabelMap> map = (*s)->segment(view);
    EXPECT_TRUE(map.ok()) << map.status().to_string();
    return map.ok() ? std::move(*map) : LabelMap{};
  };
  // The colour network works pixel by pixel, so its mirrored pass, mirrored
  // back, agrees with the plain one everywhere; a pass left mirrored would
  // move the boxes' labels across the image.
  for (const View& view : views) {
    const LabelMap plain = segment({{"model_card", dir + "/card_rgb.json"}}, view);
    const LabelMap flipped = segment({{"model_card", dir + "/card_rgb.json"}, {"flip", "on"}}, view);
    ASSERT_EQ(plain.labels.size(), view.face_id.size());
    ASSERT_EQ(flipped.labels.size(), plain.labels.size());
    for (std::size_t i = 0; i < plain.labels.size(); ++i) ASSERT_EQ(flipped.labels.data()[i], plain.labels.data()[i]);
    for (std::size_t i = 0; i < plain.probabilities.size(); ++i)
      ASSERT_NEAR(flipped.probabilities.data()[i], plain.probabilities.data()[i], 1e-5f);
  }
  // The normals network tells right-facing (Wood) from left-facing (Metal)
  // surfaces. In the mirrored view a surface facing right faces left, so the
  // two passes cancel to the network's bias, Glass, on every object pixel,
  // through `learned` as well (it hands flip to its network).
  int object = 0;
  for (const View& view : views) {
    const LabelMap plain = segment({{"model_card", dir + "/card_normals.json"}}, view);
    const LabelMap flipped = segment({{"model_card", dir + "/card_normals.json"}, {"flip", "on"}}, view);
    const LabelMap learned =
        segment({{"model_card", dir + "/card_normals.json"}, {"flip", "on"}, {"names", "off"}, {"pbr", "off"}}, view);
    ASSERT_EQ(plain.labels.size(), view.face_id.size());
    ASSERT_EQ(flipped.labels.size(), view.face_id.size());
    ASSERT_EQ(learned.labels.size(), view.face_id.size());
    int sided = 0;
    for (std::size_t i = 0; i < view.face_id.size(); ++i) {
      if (view.face_id.data()[i] < 0) continue;
      ++object;
      sided += plain.labels.data()[i] != table.find("Glass");
      ASSERT_EQ(flipped.labels.data()[i], table.find("Glass")) << "pixel " << i;
      ASSERT_EQ(learned.labels.data()[i], table.find("Glass")) << "pixel " << i;
    }
    EXPECT_GT(sided, 100);  // without flip the normals decide
  }
  EXPECT_GT(object, 1000);
  // Bad values are refused, naming the setting.
  Status bad = make_segmenter("onnx", {{"model_card", dir + "/card_rgb.json"}, {"flip", "yes"}}).status();
  EXPECT_EQ(bad.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(bad.message().find("flip"), std::string::npos) << bad.message();
  EXPECT_FALSE(make_segmenter("learned", {{"model_card", dir + "/card_rgb.json"}, {"flip", "1"}}).ok());
}

TEST(OnnxSegmenter, ModelCardErrors) {
  const std::string dir = make_model_dir();
  EXPECT_EQ(make_segmenter("onnx", {{"model_card", dir + "/none.json"}}).status().code(), StatusCode::kNotFound);
  test::write_file(dir + "/bad.json", R"({"model": "tiny_seg.onnx", "input": {"width": 32}, "classes": ["Wood"]})");
  EXPECT_EQ(make_segmenter("onnx", {{"model_card", dir + "/bad.json"}}).status().code(), StatusCode::kParseError);
  test::write_file(dir + "/missing_model.json",
                   R"({"model": "nope.onnx", "input": {"width": 32, "height": 32}, "classes": ["Wood"]})");
  EXPECT_EQ(make_segmenter("onnx", {{"model_card", dir + "/missing_model.json"}}).status().code(),
            StatusCode::kParseError);
  test::write_file(dir + "/format.json", R"({"format": "something-else", "model": "tiny_seg.onnx",
                                             "input": {"width": 32, "height": 32}, "classes": ["Wood"]})");
  EXPECT_EQ(make_segmenter("onnx", {{"model_card", dir + "/format.json"}}).status().code(), StatusCode::kParseError);
  test::write_file(dir + "/v2.json", R"({"version": 2, "model": "tiny_seg.onnx",
                                         "input": {"width": 32, "height": 32}, "classes": ["Wood"]})");
  EXPECT_EQ(make_segmenter("onnx", {{"model_card", dir + "/v2.json"}}).status().code(), StatusCode::kUnsupported);
  // Input channels the backend does not know, or one named twice.
  test::write_file(dir + "/depth.json", R"({"model": "tiny_normals.onnx", "classes": ["Wood"],
                                            "input": {"width": 32, "height": 32, "channels": ["rgb", "depth"]}})");
  Status depth = make_segmenter("onnx", {{"model_card", dir + "/depth.json"}}).status();
  EXPECT_EQ(depth.code(), StatusCode::kParseError);
  EXPECT_NE(depth.message().find("input.channels[1] is 'depth'"), std::string::npos) << depth.message();
  test::write_file(dir + "/twice.json", R"({"model": "tiny_normals.onnx", "classes": ["Wood"],
                                            "input": {"width": 32, "height": 32, "channels": ["normal", "normal"]}})");
  EXPECT_EQ(make_segmenter("onnx", {{"model_card", dir + "/twice.json"}}).status().code(), StatusCode::kParseError);
  // The card promises two classes, the network gives three channels.
  test::write_file(dir + "/two.json", R"({"model": "tiny_seg.onnx", "input": {"width": 32, "height": 32},
                                          "classes": ["Wood", "Metal"]})");
  auto two = std::move(*make_segmenter("onnx", {{"model_card", dir + "/two.json"}}));
  const Model model = rgb_boxes();
  ASSERT_TRUE(two->set_model(model, MaterialTable::paper_default()).ok());
  const std::vector<View> views = test::render(model, 1, 32);
  EXPECT_EQ(two->segment(views[0]).status().code(), StatusCode::kInvalidArgument);
  // No card at all.
  auto bare = std::move(*make_segmenter("onnx"));
  EXPECT_EQ(bare->set_model(model, MaterialTable::paper_default()).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace g2p

namespace g2p {
namespace {

// `learned`: names where they name a material, the network elsewhere. The blue
// box is called "oak" (the tiny network says Glass for blue), the red one "a".
TEST(LearnedSegmenter, NamesWhereTheyNameAMaterialTheNetworkElsewhere) {
  const std::string dir = make_model_dir();
  const Model model =
      test::boxes({{"a", {1, 0, 0, 1}, 0.f, 1.f}, {"b", {0, 1, 0, 1}, 0.f, 1.f}, {"oak", {0, 0, 1, 1}, 0.f, 1.f}},
                  "LearnedSegmenter.boxes");
  const std::vector<View> views = test::render(model, 2, 96);
  const MaterialTable& table = MaterialTable::paper_default();
  auto labels = [&](const std::string& backend, const BackendSettings& settings) {
    Result<std::unique_ptr<Segmenter>> s = make_segmenter(backend, settings);
    EXPECT_TRUE(s.ok()) << s.status().to_string();
    std::vector<LabelMap> maps(views.size());
    if (!s.ok() || !(*s)->set_model(model, table).ok()) return std::vector<int>{};
    for (std::size_t i = 0; i < views.size(); ++i) EXPECT_TRUE((*s)->segment_into(views[i], maps[i]).ok());
    return std::vector<int>{test::majority_label(model, views, maps, 0), test::majority_label(model, views, maps, 1),
                            test::majority_label(model, views, maps, 2)};
  };
  const std::string card = dir + "/card_rgb.json";
  // Names only (pbr=off): "oak" is Wood whatever the network says; the others are the network's.
  EXPECT_EQ(labels("learned", {{"model_card", card}, {"pbr", "off"}}),
            (std::vector<int>{table.find("Wood"), table.find("Metal"), table.find("Wood")}));
  // names=off too: the network alone calls the blue box Glass.
  EXPECT_EQ(labels("learned", {{"model_card", card}, {"names", "off"}, {"pbr", "off"}}),
            (std::vector<int>{table.find("Wood"), table.find("Metal"), table.find("Glass")}));
  // By default authored PBR counts: these boxes are dielectric (metallic 0, not glTF's default 1),
  // so every pixel follows pbr.
  EXPECT_EQ(labels("learned", {{"model_card", card}}), labels("pbr", {}));
  {
    // Then the network is not run at all: a view without the RGB image it needs is labelled, with
    // pbr's probabilities; with one material left to the network (pbr=off), the same view fails.
    View no_rgb = views[0];
    no_rgb.rgb.clear();
    Result<std::unique_ptr<Segmenter>> learned = make_segmenter("learned", {{"model_card", card}});
    Result<std::unique_ptr<Segmenter>> pbr = make_segmenter("pbr");
    ASSERT_TRUE(learned.ok() && pbr.ok());
    ASSERT_TRUE((*learned)->set_model(model, table).ok() && (*pbr)->set_model(model, table).ok());
    EXPECT_EQ((*learned)->image_decided_faces(), std::vector<std::uint8_t>(model.mesh.triangles.size(), 0))
        << "every face follows pbr: none is the image's";
    Result<LabelMap> a = (*learned)->segment(no_rgb), b = (*pbr)->segment(no_rgb);
    ASSERT_TRUE(a.ok()) << a.status().to_string();
    ASSERT_TRUE(b.ok()) << b.status().to_string();
    EXPECT_TRUE(a->labels == b->labels);
    EXPECT_TRUE(a->probabilities == b->probabilities);
    EXPECT_FALSE(a->labels.empty());
    Result<std::unique_ptr<Segmenter>> names_only = make_segmenter("learned", {{"model_card", card}, {"pbr", "off"}});
    ASSERT_TRUE(names_only.ok() && (*names_only)->set_model(model, table).ok());
    EXPECT_FALSE((*names_only)->segment(no_rgb).ok());
  }

  {
    // Names are read as pbr reads them: a prefix every material name shares (the object's name)
    // counts a quarter, so "WoodenCrate_steel" names Metal although "wooden" names Wood. glTF's
    // default metallic and roughness (1, 1) are not authored, so the other two boxes, whose names
    // say only "WoodenCrate", are the network's (red Wood, green Metal; it says Glass for blue).
    const Model crate = test::boxes({{"WoodenCrate_a", {1, 0, 0, 1}, 1.f, 1.f},
                                     {"WoodenCrate_b", {0, 1, 0, 1}, 1.f, 1.f},
                                     {"WoodenCrate_steel", {0, 0, 1, 1}, 1.f, 1.f}},
                                    "LearnedSegmenter.crate");
    const std::vector<View> crate_views = test::render(crate, 2, 96);
    Result<std::unique_ptr<Segmenter>> s = make_segmenter("learned", {{"model_card", card}});
    ASSERT_TRUE(s.ok() && (*s)->set_model(crate, table).ok());
    // What the `regions` refiner reads: the two boxes the network labels.
    const std::vector<std::uint8_t> image = (*s)->image_decided_faces();
    ASSERT_EQ(image.size(), crate.mesh.triangles.size());
    for (std::size_t f = 0; f < image.size(); ++f)
      EXPECT_EQ(image[f], crate.mesh.face_source[f].material == 2 ? 0 : 1) << f;
    std::vector<LabelMap> maps(crate_views.size());
    for (std::size_t i = 0; i < crate_views.size(); ++i) ASSERT_TRUE((*s)->segment_into(crate_views[i], maps[i]).ok());
    EXPECT_EQ((std::vector<int>{test::majority_label(crate, crate_views, maps, 0),
                                test::majority_label(crate, crate_views, maps, 1),
                                test::majority_label(crate, crate_views, maps, 2)}),
              (std::vector<int>{table.find("Wood"), table.find("Metal"), table.find("Metal")}));
  }

  {
    // `auto` decides per model: with one face named ("oak") `pbr` labels the whole model, where
    // `learned` gives the unnamed boxes to the network; with nothing named or authored the network
    // labels every box.
    const Model one_named =
        test::boxes({{"a", {1, 0, 0, 1}, 1.f, 1.f}, {"b", {0, 1, 0, 1}, 1.f, 1.f}, {"oak", {0, 0, 1, 1}, 1.f, 1.f}},
                    "AutoSegmenter.one_named");
    const Model unnamed =
        test::boxes({{"a", {1, 0, 0, 1}, 1.f, 1.f}, {"b", {0, 1, 0, 1}, 1.f, 1.f}, {"c", {0, 0, 1, 1}, 1.f, 1.f}},
                    "AutoSegmenter.unnamed");
    auto majority = [&](const Model& m, const std::string& backend) {
      const std::vector<View> v = test::render(m, 2, 96);
      Result<std::unique_ptr<Segmenter>> seg =
          make_segmenter(backend, backend == "pbr" ? BackendSettings{} : BackendSettings{{"model_card", card}});
      EXPECT_TRUE(seg.ok() && (*seg)->set_model(m, table).ok());
      std::vector<LabelMap> maps(v.size());
      for (std::size_t i = 0; i < v.size(); ++i) EXPECT_TRUE((*seg)->segment_into(v[i], maps[i]).ok());
      return std::vector<int>{test::majority_label(m, v, maps, 0), test::majority_label(m, v, maps, 1),
                              test::majority_label(m, v, maps, 2)};
    };
    const std::vector<int> network{table.find("Wood"), table.find("Metal"), table.find("Glass")};
    EXPECT_EQ(majority(one_named, "auto"), majority(one_named, "pbr"));
    EXPECT_EQ(majority(one_named, "learned"),
              (std::vector<int>{network[0], network[1], majority(one_named, "pbr")[2]}));
    EXPECT_NE(majority(one_named, "pbr")[0], network[0]);  // pbr says Metal (metallic 1): the checks can fail
    EXPECT_EQ(majority(unnamed, "auto"), network);
    EXPECT_EQ(majority(unnamed, "learned"), network);
  }

  {
    // An OBJ's metallic 0 and Phong roughness are the importer's, not the author's: three unnamed
    // OBJ boxes go to the network (red Wood, green Metal, blue Glass) with `learned` and `auto`.
    const std::string obj_dir = test::scratch_dir("LearnedSegmenter.obj");
    std::string obj = "mtllib boxes.mtl\n", mtl;
    const char* colours[3] = {"1 0 0", "0 1 0", "0 0 1"};
    for (int b = 0; b < 3; ++b) {
      mtl += "newmtl m" + std::to_string(b) + "\nKd " + colours[b] + "\nNs 10\n";
      const float x = 1.5f * static_cast<float>(b);
      for (int c = 0; c < 8; ++c)
        obj += "v " + std::to_string(x + float(c & 1)) + " " + std::to_string(float((c >> 1) & 1)) + " " +
               std::to_string(float((c >> 2) & 1)) + "\n";
      obj += "usemtl m" + std::to_string(b) + "\n";
      const int o = 8 * b + 1;  // the box's first vertex, 1-based
      for (const auto& q : std::vector<std::array<int, 4>>{
               {0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}})
        obj += "f " + std::to_string(o + q[0]) + " " + std::to_string(o + q[1]) + " " + std::to_string(o + q[2]) + " " +
               std::to_string(o + q[3]) + "\n";
    }
    test::write_file(obj_dir + "/boxes.obj", obj);
    test::write_file(obj_dir + "/boxes.mtl", mtl);
    Result<Model> boxes = load_model(obj_dir + "/boxes.obj");
    ASSERT_TRUE(boxes.ok()) << boxes.status().to_string();
    ASSERT_EQ(boxes->materials.size(), 3u);
    const std::vector<View> v = test::render(*boxes, 2, 96);
    auto majority = [&](const std::string& backend, const BackendSettings& settings) {
      Result<std::unique_ptr<Segmenter>> seg = make_segmenter(backend, settings);
      EXPECT_TRUE(seg.ok() && (*seg)->set_model(*boxes, table).ok());
      std::vector<LabelMap> maps(v.size());
      for (std::size_t i = 0; i < v.size(); ++i) EXPECT_TRUE((*seg)->segment_into(v[i], maps[i]).ok());
      return std::vector<int>{test::majority_label(*boxes, v, maps, 0), test::majority_label(*boxes, v, maps, 1),
                              test::majority_label(*boxes, v, maps, 2)};
    };
    const std::vector<int> network{table.find("Wood"), table.find("Metal"), table.find("Glass")};
    EXPECT_EQ(majority("learned", {{"model_card", card}}), network);
    EXPECT_EQ(majority("auto", {{"model_card", card}}), network);
    EXPECT_NE(majority("pbr", {}), network);  // pbr reads them otherwise: the checks above can fail
  }

  // Unconfigured it runs the network libg2p ships (libg2p/data/models); bad settings fail at once.
  Result<std::unique_ptr<Segmenter>> shipped = make_segmenter("learned");
  ASSERT_TRUE(shipped.ok()) << shipped.status().to_string();
  ASSERT_TRUE((*shipped)->set_model(model, table).ok());
  Result<LabelMap> map = (*shipped)->segment(views[0]);
  ASSERT_TRUE(map.ok()) << map.status().to_string();
  EXPECT_FALSE(make_segmenter("learned", {{"model_card", card}, {"names", "2"}}).ok());
  EXPECT_FALSE(make_segmenter("learned", {{"colour", "blue"}}).ok());
}

// `learned` and `auto` load their network for the first model that needs it:
// a model `pbr` labels alone never loads it, so a network OpenCV cannot read
// fails only there. The card and the network file's presence are checked at
// once, as the `onnx` backend, which loads when configured, does.
TEST(LearnedSegmenter, LoadsItsNetworkOnlyForAModelThatNeedsIt) {
  const std::string dir = make_model_dir();
  test::write_file(dir + "/broken.onnx", "not an ONNX file");
  test::write_file(dir + "/card_broken.json", R"({"model": "broken.onnx", "input": {"width": 32, "height": 32},
                                                  "classes": ["Wood", "Metal", "Glass"]})");
  const std::string card = dir + "/card_broken.json";
  const MaterialTable& table = MaterialTable::paper_default();
  Status eager = make_segmenter("onnx", {{"model_card", card}}).status();
  EXPECT_EQ(eager.code(), StatusCode::kParseError);  // the file is unreadable: the checks below can fail
  EXPECT_NE(eager.message().find("OpenCV cannot load the ONNX model"), std::string::npos) << eager.message();

  const Model authored = rgb_boxes();  // dielectric PBR (metallic 0): every face is pbr's
  const Model unnamed = test::boxes({{"a", {1, 0, 0, 1}, 1.f, 1.f}, {"b", {0, 1, 0, 1}, 1.f, 1.f}},
                                    "LearnedSegmenter.unnamed");  // glTF's defaults: the network's
  const std::vector<View> views = test::render(authored, 1, 32);
  for (const char* backend : {"learned", "auto"}) {
    Result<std::unique_ptr<Segmenter>> s = make_segmenter(backend, {{"model_card", card}});
    ASSERT_TRUE(s.ok()) << backend << ": " << s.status().to_string();
    ASSERT_TRUE((*s)->set_model(authored, table).ok()) << backend;
    Result<LabelMap> map = (*s)->segment(views[0]);
    ASSERT_TRUE(map.ok()) << backend << ": " << map.status().to_string();
    Status needs = (*s)->set_model(unnamed, table);
    EXPECT_EQ(needs.code(), StatusCode::kParseError) << backend;
    EXPECT_NE(needs.message().find(dir + "/broken.onnx: OpenCV cannot load the ONNX model"), std::string::npos)
        << needs.message();
  }

  // A card whose network file is missing fails when configured, naming the file.
  test::write_file(dir + "/card_missing.json", R"({"model": "nowhere.onnx", "input": {"width": 32, "height": 32},
                                                   "classes": ["Wood"]})");
  Status missing = make_segmenter("learned", {{"model_card", dir + "/card_missing.json"}}).status();
  EXPECT_EQ(missing.code(), StatusCode::kNotFound);
  EXPECT_NE(missing.message().find(dir + "/nowhere.onnx: the model card's network file is missing"), std::string::npos)
      << missing.message();

  // A card without a required key, or with a value of the wrong kind, says
  // which, without the JSON library's exception codes.
  test::write_file(dir + "/card_no_model.json", R"({"input": {"width": 32, "height": 32}, "classes": ["Wood"]})");
  Status no_model = make_segmenter("learned", {{"model_card", dir + "/card_no_model.json"}}).status();
  EXPECT_NE(no_model.message().find("the model card needs 'model'"), std::string::npos) << no_model.message();
  test::write_file(dir + "/card_number.json", R"({"model": 3, "input": {"width": 32, "height": 32}, "classes": []})");
  Status number = make_segmenter("learned", {{"model_card", dir + "/card_number.json"}}).status();
  EXPECT_NE(number.message().find("a value of the wrong kind (type must be string, but is number)"), std::string::npos)
      << number.message();
  EXPECT_EQ(number.message().find("json.exception"), std::string::npos) << number.message();
}

}  // namespace
}  // namespace g2p

namespace g2p {
namespace {

// The network libg2p ships: small, documented, in the table's class order,
// and loadable by OpenCV's dnn module (through the `onnx` backend) on a real
// asset stripped of names and PBR, as image-to-3D meshes arrive.
TEST(ShippedNetwork, IsSmallDocumentedAndRunsOnAStrippedAsset) {
  const std::string dir = test::source_path("libg2p/data/models");
  const nlohmann::json card = nlohmann::json::parse(test::read_file(dir + "/g2p-materials.json"));
  const MaterialTable& table = MaterialTable::paper_default();
  ASSERT_EQ(card["classes"].size(), static_cast<std::size_t>(table.size()));
  for (int c = 0; c < table.size(); ++c) EXPECT_EQ(card["classes"][c].get<std::string>(), table[c].name);
  EXPECT_LE(std::filesystem::file_size(dir + "/" + card["model"].get<std::string>()), 20u << 20);
  // training.json records one train.py run, or an ensemble (ensemble.py) and its members' runs: all
  // trained on the committed data manifest.
  const nlohmann::json training = nlohmann::json::parse(test::read_file(dir + "/training.json"));
  const bool ensemble = training.contains("ensemble");
  const nlohmann::json runs = ensemble ? training["members"] : nlohmann::json::array({training});
  ASSERT_GE(runs.size(), 1u);
  if (ensemble) EXPECT_EQ(training["ensemble"]["members"].size(), runs.size());
  bool pretrained = false;
  for (const nlohmann::json& run : runs) {
    EXPECT_EQ(run["manifest_sha256"].get<std::string>().size(), 64u);
    EXPECT_EQ(run["manifest_sha256"], runs[0]["manifest_sha256"]);
    pretrained = pretrained || run["settings"].value("context", "") != "";
  }
  const std::string attribution = test::read_file(dir + "/ATTRIBUTION.md");
  for (const char* library : {"BlendSwap-CC-0", "BlendSwap-CC-BY", "Scopia"})
    EXPECT_NE(attribution.find(library), std::string::npos) << library;
  // A network with a pretrained encoder inside (train.py --context) carries its licence and notice.
  if (pretrained) {
    const std::string notice = test::read_file(dir + "/NOTICE.md");
    for (const char* credit : {"NanoDet", "RangiLyu", "Apache License, Version 2.0", "Changes made", "Vladimir Mandic",
                               "Permission is hereby granted"})
      EXPECT_NE(notice.find(credit), std::string::npos) << credit;
    EXPECT_NE(test::read_file(dir + "/LICENSE-Apache-2.0.txt").find("TERMS AND CONDITIONS"), std::string::npos);
  }

  Result<Model> model = load_model(test::asset_path("SheenChair"));
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  anonymize_names(*model);
  for (SourceMaterial& m : model->materials) {
    m.metallic = m.roughness = 1.f;
    m.transmission = 0.f;
    m.metallic_roughness_texture = Texture{};
  }
  const std::vector<View> views = test::render(*model, 2, 128);
  auto onnx = make_segmenter("onnx", {{"model_card", dir + "/g2p-materials.json"}});
  ASSERT_TRUE(onnx.ok()) << onnx.status().to_string();
  ASSERT_TRUE((*onnx)->set_model(*model, table).ok());
  Result<LabelMap> map = (*onnx)->segment(views[0]);
  ASSERT_TRUE(map.ok()) << map.status().to_string();
  std::size_t object = 0;
  for (std::size_t i = 0; i < views[0].face_id.size(); ++i) {
    if (views[0].face_id.data()[i] < 0) continue;
    ++object;
    ASSERT_TRUE(table.valid_label(map->labels.data()[i])) << i;
    float sum = 0;
    for (int c = 0; c < table.size(); ++c) sum += map->probabilities.data()[table.size() * i + c];
    ASSERT_NEAR(sum, 1.f, 1e-4f);
  }
  EXPECT_GT(object, 1000u);
}

}  // namespace
}  // namespace g2p
