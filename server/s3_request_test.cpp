#include "s3_request.h"

#include <gtest/gtest.h>

#include <map>

namespace solidtex::server {
namespace {

S3Params params() {
  S3Params p;
  p.endpoint = "http://127.0.0.1:7070";
  p.bucket = "solidtex";
  p.prefix = "cluster/a";
  p.access_key = "K";
  p.secret_key = "S";
  return p;
}

TEST(S3Request, EncodesLikeSigV4) {
  EXPECT_EQ(uri_encode("AZaz09-._~", false), "AZaz09-._~");
  EXPECT_EQ(uri_encode("a/b c+d=e", false), "a%2Fb%20c%2Bd%3De");
  EXPECT_EQ(uri_encode("a/b c", true), "a/b%20c");
  EXPECT_EQ(uri_encode("\xc3\xa9", false), "%C3%A9");  // bytes, upper-case hex
}

TEST(S3Request, CanonicalQuerySortsAndEncodes) {
  // libcurl copies the query verbatim into what it signs: unsorted or unencoded fails with 403.
  EXPECT_EQ(canonical_query({{"prefix", "a/"}, {"list-type", "2"}}), "list-type=2&prefix=a%2F");
  // A continuation token is base64: + / = must be encoded.
  EXPECT_EQ(canonical_query({{"list-type", "2"}, {"continuation-token", "ab+c/d=="}, {"prefix", "p/exemplars/"}}),
            "continuation-token=ab%2Bc%2Fd%3D%3D&list-type=2&prefix=p%2Fexemplars%2F");
  EXPECT_EQ(canonical_query({{"b", ""}, {"a", "2"}, {"a", "1"}}), "a=1&a=2&b=");
  EXPECT_EQ(canonical_query({}), "");
}

TEST(S3Request, KeysAndUrlsArePathStyle) {
  const S3Params p = params();
  EXPECT_EQ(object_key(p.prefix, ResourceKind::kExemplar, "ex_0123", "meta.json"), "cluster/a/exemplars/ex_0123/meta.json");
  EXPECT_EQ(object_key("", ResourceKind::kField, "fld_1234", "r1.json"), "fields/fld_1234/r1.json");
  EXPECT_EQ(object_key(p.prefix, ResourceKind::kVolume, "vol_1234", ""), "cluster/a/volumes/vol_1234/");
  EXPECT_EQ(object_key(p.prefix, ResourceKind::kMesh, "", ""), "cluster/a/meshes/");
  EXPECT_EQ(object_url(p, "cluster/a/meshes/mesh_1/meta.json"), "http://127.0.0.1:7070/solidtex/cluster/a/meshes/mesh_1/meta.json");
  EXPECT_EQ(object_url(p, "", "list-type=2"), "http://127.0.0.1:7070/solidtex/?list-type=2");
}

TEST(S3Request, HeadersAlwaysCarryThePayloadHashAndNeverRemoveOne) {
  const S3Params p = params();
  const std::string empty_sha = sha256_hex({});
  EXPECT_EQ(empty_sha, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  const std::string body = "abc";
  EXPECT_EQ(sha256_hex(as_bytes(body)), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");

  auto h = request_headers(p, empty_sha);
  ASSERT_EQ(h.size(), 1u);
  EXPECT_EQ(h[0], "x-amz-content-sha256: " + empty_sha);
  h = request_headers(p, empty_sha, S3Condition::kIfNoneMatchAny);
  EXPECT_EQ(h, (std::vector<std::string>{"x-amz-content-sha256: " + empty_sha, "If-None-Match: *"}));
  h = request_headers(p, empty_sha, S3Condition::kIfMatch, "\"e1\"");
  EXPECT_EQ(h.back(), "If-Match: \"e1\"");
  S3Params with_token = p;
  with_token.session_token = "tok";
  h = request_headers(with_token, empty_sha);
  EXPECT_EQ(h.back(), "x-amz-security-token: tok");
  // curl signs every header it is given: a removal header ("Expect:") or an empty one would
  // make every request fail its signature check.
  for (const auto& line : request_headers(with_token, empty_sha, S3Condition::kIfMatch, "\"e\"")) {
    const size_t colon = line.find(':');
    ASSERT_NE(colon, std::string::npos) << line;
    EXPECT_GT(line.size(), colon + 2) << line;
  }
}

TEST(S3Request, ParamsComeFromTheUrlAndTheEnvironment) {
  std::map<std::string, std::string> env{{"AWS_ACCESS_KEY_ID", "K"}, {"AWS_SECRET_ACCESS_KEY", "S"}};
  auto getenv = [&](const char* name) -> const char* {
    auto it = env.find(name);
    return it == env.end() ? nullptr : it->second.c_str();
  };
  auto p = S3Params::from_environment("s3://bucket-1/some/prefix/", "http://h:9000/", getenv);
  ASSERT_TRUE(p.is_ok()) << p.status().to_string();
  EXPECT_EQ(p->bucket, "bucket-1");
  EXPECT_EQ(p->prefix, "some/prefix");
  EXPECT_EQ(p->endpoint, "http://h:9000");
  EXPECT_EQ(p->region, "us-east-1");
  env["AWS_REGION"] = "eu-west-3";
  env["AWS_SESSION_TOKEN"] = "T";
  p = S3Params::from_environment("s3://bucket-1", "https://s3.example", getenv);
  ASSERT_TRUE(p.is_ok());
  EXPECT_EQ(p->prefix, "");
  EXPECT_EQ(p->region, "eu-west-3");
  EXPECT_EQ(p->session_token, "T");

  auto field_of = [&](const std::string& url, const std::string& endpoint) {
    return S3Params::from_environment(url, endpoint, getenv).status().field();
  };
  EXPECT_EQ(field_of("bucket/x", "http://h"), "--storage");
  EXPECT_EQ(field_of("s3://Bad_Bucket", "http://h"), "--storage");
  EXPECT_EQ(field_of("s3://bucket/a//b", "http://h"), "--storage");
  EXPECT_EQ(field_of("s3://bucket/a b", "http://h"), "--storage");
  EXPECT_EQ(field_of("s3://bucket", ""), "--s3-endpoint");
  EXPECT_EQ(field_of("s3://bucket", "ftp://h"), "--s3-endpoint");
  EXPECT_EQ(field_of("s3://bucket", "http://h/path"), "--s3-endpoint");
  env.erase("AWS_SECRET_ACCESS_KEY");
  EXPECT_EQ(field_of("s3://bucket", "http://h"), "AWS_SECRET_ACCESS_KEY");
  env.erase("AWS_ACCESS_KEY_ID");
  EXPECT_EQ(field_of("s3://bucket", "http://h"), "AWS_ACCESS_KEY_ID");
}

TEST(S3Request, ParsesListPagesErrorsAndDates) {
  const std::string xml =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?><ListBucketResult xmlns=\"http://s3.amazonaws.com/doc/2006-03-01/\">"
      "<Name>solidtex</Name><Prefix>p/exemplars/</Prefix><KeyCount>2</KeyCount><IsTruncated>true</IsTruncated>"
      "<Contents><Key>p/exemplars/ex_1/meta.json</Key><LastModified>2026-12-02T10:00:01.500Z</LastModified>"
      "<ETag>&quot;abc&quot;</ETag><Size>3</Size></Contents>"
      "<Contents><Key>p/exemplars/ex_1/a&amp;b</Key><LastModified>2026-12-02T10:00:00Z</LastModified></Contents>"
      "<NextContinuationToken>tok+/=</NextContinuationToken></ListBucketResult>";
  auto page = parse_list_page(xml);
  ASSERT_TRUE(page.is_ok()) << page.status().to_string();
  ASSERT_EQ(page->objects.size(), 2u);
  EXPECT_EQ(page->objects[0].key, "p/exemplars/ex_1/meta.json");
  EXPECT_EQ(page->objects[1].key, "p/exemplars/ex_1/a&b");
  EXPECT_DOUBLE_EQ(page->objects[0].last_modified - page->objects[1].last_modified, 1.5);
  EXPECT_TRUE(page->truncated);
  EXPECT_EQ(page->next_token, "tok+/=");
  EXPECT_FALSE(parse_list_page("<Error><Code>AccessDenied</Code></Error>").is_ok());
  auto empty = parse_list_page("<ListBucketResult><IsTruncated>false</IsTruncated></ListBucketResult>");
  ASSERT_TRUE(empty.is_ok());
  EXPECT_TRUE(empty->objects.empty());

  const S3ErrorBody e = parse_error_body(
      "<?xml version=\"1.0\"?><Error><Code>PreconditionFailed</Code><Message>At least one of the pre-conditions "
      "you specified did not hold</Message></Error>");
  EXPECT_EQ(e.code, "PreconditionFailed");
  EXPECT_NE(e.message.find("pre-conditions"), std::string::npos);

  EXPECT_DOUBLE_EQ(parse_iso8601("1970-01-02T00:00:00.000Z"), 86400);
  EXPECT_DOUBLE_EQ(parse_http_date("Fri, 02 Jan 1970 00:00:10 GMT"), 86410);
  EXPECT_LT(parse_http_date("yesterday"), 0);
  EXPECT_LT(parse_iso8601(""), 0);
}

}  // namespace
}  // namespace solidtex::server
