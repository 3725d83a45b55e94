// The `vlm` refiner against a real HTTP server on 127.0.0.1 (cpp-httplib)
// that checks each request and answers with scripted replies.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <functional>
#include <nlohmann/json.hpp>
#include <thread>

#include "g2p/refine.h"
#include "g2p/vlm.h"
#include "segment/segment_fixtures.h"
#include "support/test_data.h"

// After Eigen: httplib pulls in <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include "support/fake_vlm_server.h"

namespace g2p {
namespace {

using nlohmann::json;

using test::FakeVlmServer;

// The hammer with its head mislabelled Plastic (handle Wood), seen from 2 views.
struct Scene {
  Model model;
  std::vector<View> views;
  FaceLabels labels;
};

Scene hammer() {
  Scene s;
  s.model = *load_model(test::source_path("examples/data/hammer.obj"));
  s.views = test::render(s.model, 2, 64);
  const MaterialTable& t = MaterialTable::paper_default();
  for (const FaceSource& f : s.model.mesh.face_source)
    s.labels.label.push_back(f.material == 0 ? t.find("Wood") : t.find("Plastic"));
  s.labels.confidence.assign(s.labels.label.size(), 1.f);
  s.labels.seen.assign(s.labels.label.size(), 1);
  return s;
}

Result<RefineResult> run(const Scene& s, const std::string& url, BackendSettings extra = {}) {
  BackendSettings settings = {{"url", url},        {"model", "test-vlm"}, {"timeout", "5"},
                              {"backoff", "0.01"}, {"retries", "2"},      {"api_key_env", "G2P_TEST_VLM_KEY"}};
  for (const auto& [k, v] : extra) settings[k] = v;
  Result<std::unique_ptr<Refiner>> r = make_refiner("vlm", settings);
  if (!r.ok()) return r.status();
  RefineInput in;
  in.mesh = &s.model.mesh;
  in.labels = &s.labels;
  in.views = &s.views;
  in.table = &MaterialTable::paper_default();
  return (*r)->refine(in);
}

std::string notes(const RefineResult& r) {
  std::string all;
  for (const std::string& n : r.notes) all += n + "\n";
  return all;
}

const char* kValid =
    "This is a hammer: a wooden handle and a steel head.\n```json\n"
    R"({"object": "hammer", "corrections": [{"from": "Plastic", "to": "Metal", "reason": "steel head"}]})"
    "\n```";

TEST(VlmRefiner, AppliesAValidCorrectionAndSendsAWellFormedRequest) {
  const Scene s = hammer();
  FakeVlmServer server([](int, const json&, httplib::Response& res) { FakeVlmServer::answer(res, kValid); });
  ::setenv("G2P_TEST_VLM_KEY", "sekret-key-123", 1);
  Result<RefineResult> r = run(s, server.url());
  ::unsetenv("G2P_TEST_VLM_KEY");
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  const MaterialTable& t = MaterialTable::paper_default();
  int metal = 0;
  for (std::size_t f = 0; f < r->labels.size(); ++f) {
    EXPECT_EQ(r->labels[f], s.model.mesh.face_source[f].material == 0 ? t.find("Wood") : t.find("Metal"));
    metal += r->labels[f] == t.find("Metal");
  }
  EXPECT_EQ(metal, 12);
  ASSERT_EQ(r->changes.size(), 12u);
  EXPECT_NE(r->changes[0].reason.find("steel head"), std::string::npos);
  // The request: model, temperature 0, the prompt, two images per view as PNG data URLs.
  const json& req = server.last_request();
  EXPECT_EQ(req["model"], "test-vlm");
  EXPECT_EQ(req["temperature"].get<double>(), 0.0);
  int images = 0;
  std::string text;
  for (const json& part : req["messages"].back()["content"]) {
    if (part["type"] == "image_url") {
      EXPECT_EQ(part["image_url"]["url"].get<std::string>().rfind("data:image/png;base64,iVBOR", 0), 0u);
      ++images;
    } else {
      text += part["text"].get<std::string>();
    }
  }
  EXPECT_EQ(images, 4);
  EXPECT_NE(text.find("\"corrections\""), std::string::npos);
  EXPECT_NE(text.find("Wood, Rubber, Fabric"), std::string::npos);  // the vocabulary
  EXPECT_NE(text.find("Plastic: "), std::string::npos);             // the current summary
  // The key goes in the header and nowhere else.
  EXPECT_EQ(server.authorization(), "Bearer sekret-key-123");
  EXPECT_EQ(notes(*r).find("sekret"), std::string::npos);
}

TEST(VlmRefiner, LeavesTheViewsAsTheyWere) {
  // The refiner encodes each view it sends as PNG; that must not touch the
  // caller's pixels (it once swapped red and blue in place, so the saved
  // views turned blue and the next request sent the wrong colours).
  const Scene s = hammer();
  std::vector<ImageU8> before;
  for (const View& v : s.views) before.push_back(v.rgb);
  std::vector<std::string> first_images;
  FakeVlmServer server([&](int, const json& request, httplib::Response& res) {
    for (const json& part : request["messages"].back()["content"])
      if (part["type"] == "image_url") {
        first_images.push_back(part["image_url"]["url"].get<std::string>());
        break;
      }
    FakeVlmServer::answer(res, kValid);
  });
  for (int round = 0; round < 2; ++round) ASSERT_TRUE(run(s, server.url()).ok());
  for (std::size_t i = 0; i < s.views.size(); ++i) {
    ASSERT_EQ(s.views[i].rgb.size(), before[i].size());
    EXPECT_TRUE(std::equal(before[i].data(), before[i].data() + before[i].size(), s.views[i].rgb.data()))
        << "view " << i << " changed";
  }
  ASSERT_EQ(first_images.size(), 2u);
  EXPECT_EQ(first_images[0], first_images[1]);  // the same view, the same PNG, each time
}

TEST(VlmRefiner, RetriesAfter429) {
  const Scene s = hammer();
  FakeVlmServer server([](int attempt, const json&, httplib::Response& res) {
    if (attempt == 0) {
      res.status = 429;
      res.set_header("Retry-After", "0");
      res.set_content("slow down", "text/plain");
    } else {
      FakeVlmServer::answer(res, kValid);
    }
  });
  Result<RefineResult> r = run(s, server.url());
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(server.attempts(), 2);
  EXPECT_EQ(r->changes.size(), 12u);
}

// Each failure leaves the labels as they were and says what happened.
struct FailureCase {
  const char* name;
  FakeVlmServer::Reply reply;
  BackendSettings extra;
  const char* note;
};

class VlmFailures : public testing::TestWithParam<FailureCase> {};

TEST_P(VlmFailures, LoseNothingAndReport) {
  const Scene s = hammer();
  FakeVlmServer server(GetParam().reply);
  Result<RefineResult> r = run(s, server.url(), GetParam().extra);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_EQ(r->labels, s.labels.label);
  EXPECT_TRUE(r->changes.empty());
  EXPECT_NE(notes(*r).find(GetParam().note), std::string::npos) << notes(*r);
}

INSTANTIATE_TEST_SUITE_P(Scripted, VlmFailures,
                         testing::Values(FailureCase{"malformed_json",
                                                     [](int, const json&, httplib::Response& res) {
                                                       FakeVlmServer::answer(
                                                           res, "Looks fine to me {\"corrections\": [ {\"from\": ");
                                                     },
                                                     {},
                                                     "rejected the answer"},
                                         FailureCase{"server_error",
                                                     [](int, const json&, httplib::Response& res) {
                                                       res.status = 500;
                                                       res.set_content("boom", "text/plain");
                                                     },
                                                     {},
                                                     "HTTP 500 (gave up after 3 attempts)"},
                                         FailureCase{"timeout",
                                                     [](int, const json&, httplib::Response& res) {
                                                       std::this_thread::sleep_for(std::chrono::milliseconds(1500));
                                                       FakeVlmServer::answer(res, kValid);
                                                     },
                                                     {{"timeout", "0.3"}},
                                                     "no answer from"},
                                         FailureCase{"ten_megabytes",
                                                     [](int, const json&, httplib::Response& res) {
                                                       FakeVlmServer::answer(res, std::string(10u << 20, 'x'));
                                                     },
                                                     {},
                                                     "exceeds 4194304 bytes"},
                                         FailureCase{
                                             "unknown_class",
                                             [](int, const json&, httplib::Response& res) {
                                               FakeVlmServer::answer(
                                                   res, R"({"corrections": [{"from": "Plastic", "to": "Vibranium"}]})");
                                             },
                                             {},
                                             "outside the vocabulary"},
                                         FailureCase{"refusal",
                                                     [](int, const json&, httplib::Response& res) {
                                                       FakeVlmServer::answer(res, "I cannot help with that.");
                                                     },
                                                     {},
                                                     "rejected the answer"}),
                         [](const testing::TestParamInfo<FailureCase>& info) { return std::string(info.param.name); });

TEST(VlmRefiner, UnreachableServerAndBadSettings) {
  const Scene s = hammer();
  Result<RefineResult> r = run(s, "http://127.0.0.1:9/v1", {{"retries", "0"}});  // discard port: refused
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->labels, s.labels.label);
  EXPECT_NE(notes(*r).find("labels stand"), std::string::npos) << notes(*r);
  EXPECT_EQ(make_refiner("vlm", {{"model", "m"}, {"url", "ftp://x"}}).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(make_refiner("vlm", {{"temperature", "2"}}).status().code(), StatusCode::kInvalidArgument);
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{{"timeout", "inf"},
                                                                                   {"timeout", "0.00001"},
                                                                                   {"retries", "1.5"},
                                                                                   {"max_response_bytes", "-1"},
                                                                                   {"backoff", "-2"},
                                                                                   {"max_views", "0"}})
    EXPECT_EQ(make_refiner("vlm", {{"model", "m"}, {key, value}}).status().code(), StatusCode::kInvalidArgument)
        << key << "=" << value;
  // No model named: refused when made (as the pipeline is prepared), not when it is first asked.
  Result<std::unique_ptr<Refiner>> unconfigured = make_refiner("vlm", {{"url", "http://127.0.0.1:9/v1"}});
  ASSERT_FALSE(unconfigured.ok());
  EXPECT_EQ(unconfigured.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(unconfigured.status().message().find("model=NAME"), std::string::npos) << unconfigured.status().to_string();
}

TEST(VlmHelpers, RedactUrl) {
  EXPECT_EQ(redact_url("http://127.0.0.1:8000/v1"), "http://127.0.0.1:8000/v1");
  EXPECT_EQ(redact_url("https://user:pass@host/v1"), "https://***@host/v1");
  EXPECT_EQ(redact_url("https://host/v1?key=abc&api-version=2&flag"), "https://host/v1?key=***&api-version=***&flag");
  EXPECT_EQ(redact_url("https://u@host:443/p?token=t#frag"), "https://***@host:443/p?token=***#***");
  EXPECT_EQ(redact_url("https://host/v1#access_token=PW4SECRET"), "https://host/v1#***");
  EXPECT_EQ(redact_url("https://host/a@b"), "https://host/a@b");  // an @ in the path is no user
}

TEST(VlmRefiner, AKeyInTheUrlReachesTheServerAndNoMessage) {
  const Scene s = hammer();
  FakeVlmServer server([&](int, const json&, httplib::Response& res) { res.status = 503; });
  Result<RefineResult> r = run(s, server.url() + "?key=qk-secret-99", {{"retries", "0"}});
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_TRUE(r->fell_back);
  EXPECT_EQ(server.attempts(), 1);  // the endpoint's path went before the query: the server was reached
  EXPECT_EQ(notes(*r).find("qk-secret-99"), std::string::npos) << notes(*r);
  EXPECT_NE(notes(*r).find("chat/completions?key=***"), std::string::npos) << notes(*r);
}

// Servers echo what they were sent in their errors ("Incorrect API key
// provided: sk-..."), and error pages are cut to 300 bytes: the message keeps
// neither the key nor a broken character, so JSON writers and logs take it.
TEST(VlmRefiner, AServersErrorNeitherRepeatsTheKeyNorBreaksTheText) {
  const Scene s = hammer();
  ::setenv("G2P_TEST_VLM_KEY", "sk-SECRETKEY123", 1);
  FakeVlmServer echo([](int, const json&, httplib::Response& res) {
    res.status = 401;
    res.set_content("{\"error\": \"Incorrect API key provided: sk-SECRETKEY123 (header: Bearer sk-SECRETKEY123)\"}",
                    "application/json");
  });
  Result<RefineResult> r = run(s, echo.url(), {{"retries", "0"}});
  ::unsetenv("G2P_TEST_VLM_KEY");
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_TRUE(r->fell_back);
  EXPECT_EQ(notes(*r).find("SECRETKEY123"), std::string::npos) << notes(*r);
  EXPECT_NE(notes(*r).find("HTTP 401: {\"error\": \"Incorrect API key provided: ***"), std::string::npos) << notes(*r);

  // 299 bytes, then an "é" that the 300-byte cut would split, then a Latin-1 byte.
  FakeVlmServer page([](int, const json&, httplib::Response& res) {
    res.status = 403;
    res.set_content(std::string(299, 'a') + "\xc3\xa9 Zugriff verweigert \xe9", "text/html");
  });
  r = run(s, page.url(), {{"retries", "0"}});
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_NE(notes(*r).find(std::string(299, 'a') + "..."), std::string::npos) << notes(*r);
  EXPECT_NO_THROW(json(notes(*r)).dump());  // strict: throws on bytes that are not UTF-8
}

TEST(VlmHelpers, JsonExtractionAndBase64) {
  EXPECT_EQ(*extract_json_object("reasoning...\n```json\n{\"a\": 1}\n```\n"), "\n{\"a\": 1}\n");
  EXPECT_EQ(*extract_json_object("first {\"x\": {\"y\": 2}} then {\"z\": 3} done"), "{\"z\": 3}");
  EXPECT_EQ(*extract_json_object("nested {\"x\": {\"y\": 2}}"), "{\"x\": {\"y\": 2}}");
  EXPECT_FALSE(extract_json_object("no json here").ok());
  EXPECT_EQ(base64_encode(""), "");
  EXPECT_EQ(base64_encode("f"), "Zg==");
  EXPECT_EQ(base64_encode("fo"), "Zm8=");
  EXPECT_EQ(base64_encode("foobar"), "Zm9vYmFy");
}

}  // namespace
}  // namespace g2p
