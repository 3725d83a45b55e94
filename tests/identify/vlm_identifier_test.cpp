// The `vlm` identifier against a scripted chat-completions server on 127.0.0.1.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "g2p/identify.h"
#include "g2p/io.h"
#include "g2p/pipeline.h"
#include "support/test_data.h"

// After Eigen (httplib's <resolv.h>).
#include "support/fake_vlm_server.h"

namespace g2p {
namespace {

using test::FakeVlmServer;

Result<PipelineResult> rendered_hammer(PipelineOptions o) {
  o.last_stage = Stage::kRender;
  o.views.num_views = 4;
  o.views.width = o.views.height = 96;
  return Pipeline(o).run_file(test::source_path("examples/data/hammer.obj"));
}

TEST(VlmIdentifier, TheModelsWordsBecomeAKindAndItsViewsAreSent) {
  FakeVlmServer server([](int, const nlohmann::json&, httplib::Response& res) {
    FakeVlmServer::answer(
        res, "It looks like a claw hammer.\n```json\n{\"object\": \"claw hammer\", \"confidence\": 0.8}\n```");
  });
  Result<PipelineResult> r = rendered_hammer({});
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  Result<std::unique_ptr<Identifier>> vlm = make_identifier("vlm", {{"url", server.url()}, {"model", "test"}});
  ASSERT_TRUE(vlm.ok()) << vlm.status().to_string();
  IdentifyInput in;
  in.model = &r->model;
  in.views = &r->views;
  Result<Identification> id = (*vlm)->identify(in);
  ASSERT_TRUE(id.ok()) << id.status().to_string();
  EXPECT_EQ(id->kind(), "hammer");
  EXPECT_EQ(id->source(), "vlm");
  EXPECT_DOUBLE_EQ(id->confidence(), 0.8);
  // The request carried the views as images (up to max_views, 4).
  int images = 0;
  for (const auto& part : server.last_request()["messages"][1]["content"]) images += part["type"] == "image_url";
  EXPECT_EQ(images, 4);
}

TEST(VlmIdentifier, AnUnusableAnswerOrNoServerLeavesTheObjectUnknownWithAWarning) {
  Result<PipelineResult> r = rendered_hammer({});
  ASSERT_TRUE(r.ok());
  IdentifyInput in;
  in.model = &r->model;
  in.views = &r->views;
  {
    FakeVlmServer server(
        [](int, const nlohmann::json&, httplib::Response& res) { FakeVlmServer::answer(res, "I cannot tell."); });
    Result<std::unique_ptr<Identifier>> vlm = make_identifier("vlm", {{"url", server.url()}, {"model", "test"}});
    ASSERT_TRUE(vlm.ok());
    Result<Identification> id = (*vlm)->identify(in);
    ASSERT_TRUE(id.ok());
    EXPECT_FALSE(id->known());
    ASSERT_EQ(id->warnings.size(), 1u);
    EXPECT_NE(id->warnings[0].find("no JSON object"), std::string::npos) << id->warnings[0];
  }
  // Nothing listens there: a warning, and the pipeline goes on.
  PipelineOptions o;
  o.identifier = {"vlm", {{"url", "http://127.0.0.1:9/v1"}, {"model", "test"}, {"retries", "0"}, {"timeout", "2"}}};
  o.last_stage = Stage::kIdentify;
  o.views.num_views = 2;
  o.views.width = o.views.height = 64;
  Result<PipelineResult> p = Pipeline(o).run_file(test::source_path("examples/data/hammer.obj"));
  ASSERT_TRUE(p.ok()) << p.status().to_string();
  EXPECT_FALSE(p->identification.known());
  bool warned = false;
  for (const std::string& w : p->warnings) warned |= w.rfind("identify: vlm: no answer", 0) == 0;
  EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace g2p
