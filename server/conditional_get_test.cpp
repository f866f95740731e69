#include "conditional_get.h"

#include <gtest/gtest.h>

namespace solidtex::server {
namespace {

HttpResponse chunk() {
  HttpResponse r;
  r.content_type = "application/octet-stream";
  r.body = "0123456789";
  r.headers = {{"ETag", "\"v1-zarr3-0-1.2.3\""}, {"Cache-Control", "public, immutable"}, {"Access-Control-Allow-Origin", "*"}};
  return r;
}

std::string header(const HttpResponse& r, const std::string& name) {
  for (const auto& [k, v] : r.headers)
    if (k == name) return v;
  return "<none>";
}

TEST(ConditionalGet, WholeAnswerSaysItAcceptsRanges) {
  const HttpResponse out = conditional_get(HttpRequest{}, chunk());
  EXPECT_EQ(out.status, 200);
  EXPECT_EQ(out.body, "0123456789");
  EXPECT_EQ(header(out, "Accept-Ranges"), "bytes");
  EXPECT_EQ(out.content_length, -1);
}

TEST(ConditionalGet, MatchingIfNoneMatchIsNotModifiedWithTheHeadersKept) {
  HttpRequest r;
  for (const char* h : {"\"v1-zarr3-0-1.2.3\"", "\"other\", W/\"v1-zarr3-0-1.2.3\"", "*"}) {
    r.if_none_match = h;
    const HttpResponse out = conditional_get(r, chunk());
    EXPECT_EQ(out.status, 304) << h;
    EXPECT_TRUE(out.body.empty());
    EXPECT_EQ(out.content_length, 10);  // what a 200 would carry
    EXPECT_EQ(header(out, "ETag"), "\"v1-zarr3-0-1.2.3\"");
    EXPECT_EQ(header(out, "Cache-Control"), "public, immutable");
    EXPECT_EQ(header(out, "Access-Control-Allow-Origin"), "*");
  }
  r.if_none_match = "\"v1-zarr3-0-1.2.4\"";
  EXPECT_EQ(conditional_get(r, chunk()).status, 200);
}

TEST(ConditionalGet, RangeGivesPartialContentOrUnsatisfiable) {
  HttpRequest r;
  r.range = "bytes=2-4";
  HttpResponse out = conditional_get(r, chunk());
  EXPECT_EQ(out.status, 206);
  EXPECT_EQ(out.body, "234");
  EXPECT_EQ(header(out, "Content-Range"), "bytes 2-4/10");
  EXPECT_EQ(header(out, "ETag"), "\"v1-zarr3-0-1.2.3\"");
  r.range = "bytes=-3";
  EXPECT_EQ(conditional_get(r, chunk()).body, "789");
  r.range = "bytes=10-";
  out = conditional_get(r, chunk());
  EXPECT_EQ(out.status, 416);
  EXPECT_EQ(header(out, "Content-Range"), "bytes */10");
  EXPECT_EQ(header(out, "Access-Control-Allow-Origin"), "*");
  EXPECT_EQ(header(out, "Cache-Control"), "<none>");  // a refusal is not immutable
  EXPECT_NE(out.body.find("range_not_satisfiable"), std::string::npos);
  r.range = "bytes=0-1,4-5";  // several ranges: the whole body
  out = conditional_get(r, chunk());
  EXPECT_EQ(out.status, 200);
  EXPECT_EQ(out.body, "0123456789");
}

TEST(ConditionalGet, IfRangeNamingAnotherTagMeansTheWholeBody) {
  HttpRequest r;
  r.range = "bytes=0-0";
  r.if_range = "\"v1-zarr3-0-1.2.3\"";
  EXPECT_EQ(conditional_get(r, chunk()).status, 206);
  for (const char* h : {"\"stale\"", "W/\"v1-zarr3-0-1.2.3\"", "Tue, 15 Nov 1994 08:12:31 GMT"}) {
    r.if_range = h;
    EXPECT_EQ(conditional_get(r, chunk()).status, 200) << h;
  }
}

TEST(ConditionalGet, ErrorsPassThrough) {
  HttpResponse err = HttpResponse::error(Status(StatusCode::kNotFound, "outside", "chunk"));
  HttpRequest r;
  r.range = "bytes=0-1";
  r.if_none_match = "*";
  const HttpResponse out = conditional_get(r, err);
  EXPECT_EQ(out.status, 404);
  EXPECT_EQ(out.body, err.body);
  EXPECT_EQ(header(out, "Accept-Ranges"), "<none>");
}

}  // namespace
}  // namespace solidtex::server
