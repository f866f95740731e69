// The route table and proto/openapi.json describe the same API, and the served document is
// the file.
#include "routes.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <set>
#include <sstream>

#include "openapi_document.h"

namespace solidtex::server {
namespace {

std::string read_openapi_file() {
  std::ifstream in(std::string(SOLIDTEX_SOURCE_DIR) + "/proto/openapi.json");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Routes, TableAndOpenApiDocumentListTheSameOperations) {
  const auto doc = nlohmann::json::parse(read_openapi_file());
  std::set<std::pair<std::string, std::string>> documented, routed;
  for (auto& [path, ops] : doc["paths"].items())
    for (auto& [method, op] : ops.items())
      if (method != "parameters") {
        std::string m = method;
        for (char& c : m) c = char(std::toupper(c));
        documented.insert({m, path});
        EXPECT_TRUE(op.contains("operationId")) << m << " " << path;
        EXPECT_TRUE(op.contains("responses")) << m << " " << path;
      }
  for (const Route& r : route_table()) routed.insert({r.method, r.path});
  EXPECT_EQ(documented, routed);
}

TEST(Routes, ServedDocumentIsTheContractFile) {
  // Compared as a whole but reported briefly (the document is large); a mismatch means the
  // build did not re-embed proto/openapi.json.
  EXPECT_TRUE(std::string(openapi_document()) == read_openapi_file()) << "served document differs from proto/openapi.json";
}

TEST(Routes, MatchesTemplatesAndReportsAllowedMethods) {
  std::map<std::string, std::string> params;
  std::vector<std::string> allowed;
  const Route* r = match_route("GET", "/v1/volumes/vol_1234/slice", params, allowed);
  ASSERT_NE(r, nullptr);
  EXPECT_STREQ(r->path, "/v1/volumes/{id}/slice");
  EXPECT_EQ(params.at("id"), "vol_1234");

  allowed.clear();
  EXPECT_EQ(match_route("PUT", "/v1/volumes", params, allowed), nullptr);
  EXPECT_EQ(std::set<std::string>(allowed.begin(), allowed.end()), (std::set<std::string>{"GET", "HEAD", "POST"}));

  // HEAD is answered by the GET route; a path without GET has no HEAD.
  allowed.clear();
  r = match_route("HEAD", "/v1/volumes/vol_1/zarr/0/c/0/1/2/3", params, allowed);
  ASSERT_NE(r, nullptr);
  EXPECT_STREQ(r->method, "GET");
  EXPECT_EQ(params.at("cx"), "3");
  allowed.clear();
  EXPECT_EQ(match_route("HEAD", "/v1/volumes/vol_1/cut", params, allowed), nullptr);
  EXPECT_EQ(allowed, (std::vector<std::string>{"POST"}));

  // A literal path belongs to its own route only: not also to /v1/fields/{id}.
  allowed.clear();
  EXPECT_EQ(match_route("GET", "/v1/fields/from-mesh", params, allowed), nullptr);
  EXPECT_EQ(allowed, (std::vector<std::string>{"POST"}));
  allowed.clear();
  r = match_route("GET", "/v1/fields/fld_1", params, allowed);
  ASSERT_NE(r, nullptr);
  EXPECT_STREQ(r->path, "/v1/fields/{id}");

  allowed.clear();
  EXPECT_EQ(match_route("GET", "/v1/nothing/here", params, allowed), nullptr);
  EXPECT_TRUE(allowed.empty());
}

TEST(Routes, TheWebAppOwnsTheRootAndWebFilesOnly) {
  std::map<std::string, std::string> params;
  std::vector<std::string> allowed;
  const Route* r = match_route("GET", "/", params, allowed);
  ASSERT_NE(r, nullptr);
  EXPECT_STREQ(r->path, "/");
  EXPECT_EQ(r->execution, Execution::kInline);  // the page loads while every worker synthesizes
  r = match_route("GET", "/web/app.js", params, allowed);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(params.at("file"), "app.js");
  EXPECT_EQ(r->execution, Execution::kInline);
  // One segment only: a nested or traversing path matches no route at all.
  allowed.clear();
  EXPECT_EQ(match_route("GET", "/web/a/b.js", params, allowed), nullptr);
  EXPECT_TRUE(allowed.empty());
  EXPECT_EQ(match_route("GET", "/web/../v1/volumes", params, allowed), nullptr);
  // The root is not a catch-all: unknown paths stay unrouted (404).
  allowed.clear();
  EXPECT_EQ(match_route("GET", "/index.html", params, allowed), nullptr);
  EXPECT_TRUE(allowed.empty());
  allowed.clear();
  r = match_route("DELETE", "/v1/fields/fld_1/curves/last", params, allowed);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(params.at("id"), "fld_1");
}

}  // namespace
}  // namespace solidtex::server
