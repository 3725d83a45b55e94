#include "g2p/status.h"

#include <gtest/gtest.h>

#include <memory>
#include <set>

namespace g2p {
namespace {

TEST(Status, DefaultIsOk) {
  Status s;
  EXPECT_TRUE(s.ok());
  EXPECT_EQ(s.code(), StatusCode::kOk);
  EXPECT_EQ(s.to_string(), "ok");
}

TEST(Status, ErrorCarriesCodeAndMessage) {
  const Status s = Status::ParseError("mesh 3 face 17: index 912 out of range (512 vertices)");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.code(), StatusCode::kParseError);
  EXPECT_EQ(s.to_string(), "parse error: mesh 3 face 17: index 912 out of range (512 vertices)");
}

TEST(Status, WithContextPrefixesErrorsOnly) {
  EXPECT_EQ(Status::NotFound("no such file").with_context("a.glb").message(), "a.glb: no such file");
  EXPECT_TRUE(Status::Ok().with_context("a.glb").ok());
  EXPECT_EQ(Status::Ok().with_context("a.glb").message(), "");
}

TEST(Status, EveryCodeHasADistinctName) {
  const StatusCode codes[] = {StatusCode::kOk,        StatusCode::kInvalidArgument, StatusCode::kNotFound,
                              StatusCode::kIoError,   StatusCode::kParseError,      StatusCode::kUnsupported,
                              StatusCode::kCancelled, StatusCode::kUnavailable,     StatusCode::kInternal};
  std::set<std::string> names;
  for (StatusCode c : codes) names.insert(to_string(c));
  EXPECT_EQ(names.size(), std::size(codes));
}

Result<int> parse_positive(int x) {
  if (x <= 0) return Status::InvalidArgument("x = " + std::to_string(x) + " is not positive");
  return x;
}

Status twice_positive(int x, int* out) {
  Result<int> r = parse_positive(x);
  G2P_RETURN_IF_ERROR(r.status());
  *out = 2 * *r;
  return Status::Ok();
}

TEST(Result, HoldsValueOrStatus) {
  Result<int> good = parse_positive(4);
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(*good, 4);
  EXPECT_TRUE(good.status().ok());

  Result<int> bad = parse_positive(-1);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(bad.status().message(), "x = -1 is not positive");
  EXPECT_EQ(bad.value_or(7), 7);
}

TEST(Result, FromOkStatusBecomesInternalError) {
  Result<int> r{Status::Ok()};
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInternal);
}

TEST(Result, MovesOutMoveOnlyValues) {
  Result<std::unique_ptr<int>> r = std::make_unique<int>(5);
  ASSERT_TRUE(r.ok());
  std::unique_ptr<int> p = std::move(r).value();
  EXPECT_EQ(*p, 5);
}

TEST(Result, ReturnIfErrorPropagatesTheFirstError) {
  int out = 0;
  EXPECT_TRUE(twice_positive(3, &out).ok());
  EXPECT_EQ(out, 6);
  const Status s = twice_positive(0, &out);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(out, 6);  // untouched by the failed call
}

}  // namespace
}  // namespace g2p
