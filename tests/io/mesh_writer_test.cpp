// write_mesh: every format reads back (through assimp) with the same geometry.
#include <gtest/gtest.h>

#include "g2p/io.h"
#include "g2p/properties.h"
#include "support/gltf_builder.h"
#include "support/test_data.h"

namespace g2p {
namespace {

TEST(WriteMesh, RoundTripsObjPlyAndStl) {
  const Mesh sphere = test::sphere_mesh(0.25, 12);
  const double volume = solid_mass_properties(sphere, 1.0)->volume_m3;
  const std::string dir = test::scratch_dir("WriteMesh");
  for (const char* ext : {"obj", "ply", "stl"}) {
    SCOPED_TRACE(ext);
    const std::string path = dir + "/sphere." + ext;
    ASSERT_TRUE(write_mesh(path, sphere).ok());
    ImportOptions io;
    io.z_up = false;
    io.unit_scale = 1.0;
    io.up_axis = UpAxis::kZ;
    Result<Model> back = load_model(path, io);
    ASSERT_TRUE(back.ok()) << back.status().to_string();
    EXPECT_EQ(back->mesh.num_faces(), sphere.num_faces());
    EXPECT_NEAR(solid_mass_properties(back->mesh, 1.0)->volume_m3 / volume, 1.0, 1e-5);
  }
}

TEST(WriteMesh, RefusesUnknownExtensionsAndBadMeshes) {
  const std::string dir = test::scratch_dir("WriteMeshBad");
  EXPECT_EQ(write_mesh(dir + "/a.fbx", test::box_mesh({0, 0, 0}, {1, 1, 1})).code(), StatusCode::kInvalidArgument);
  Mesh bad = test::box_mesh({0, 0, 0}, {1, 1, 1});
  bad.triangles[3][1] = 42;
  const Status s = write_mesh(dir + "/a.obj", bad);
  EXPECT_FALSE(s.ok());
}

}  // namespace
}  // namespace g2p
