// The parts of an S3 request solidtex builds itself, apart from the transport (s3_storage.cpp,
// the only file that includes libcurl), so they can be tested without a server.
//
// libcurl's CURLOPT_AWS_SIGV4 signs the request, but (libcurl 7.88, measured in
// docs/design/scale-out-research.md) it copies the query string verbatim into the canonical
// request, does not send x-amz-content-sha256, and signs every header it is given, removal
// headers ("Expect:") included. So: canonical_query() sorts and percent-encodes the query;
// request_headers() always sends x-amz-content-sha256 (the body's hex SHA-256, which the
// server verifies) and never a removal header; object keys are kept to [A-Za-z0-9._/-] and
// encoded by uri_encode() anyway. URLs are path-style: endpoint/bucket/key.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/status.h"
#include "storage.h"

namespace solidtex::server {

// Where and as whom: --storage s3://bucket/prefix, --s3-endpoint, and the environment.
struct S3Params {
  std::string endpoint;       // http(s)://host[:port], no path, no trailing slash
  std::string bucket;         // S3 bucket naming rules: [a-z0-9.-], 3..63 characters
  std::string prefix;         // key prefix without leading or trailing '/'; may be empty
  std::string region = "us-east-1";  // AWS_REGION
  std::string access_key;     // AWS_ACCESS_KEY_ID
  std::string secret_key;     // AWS_SECRET_ACCESS_KEY
  std::string session_token;  // AWS_SESSION_TOKEN (optional): sent as x-amz-security-token
  double connect_timeout_s = 5;  // per connection attempt, (0, 600]
  // A transfer slower than 1 KiB/s for this long is abandoned, seconds, (0, 3600] (no total
  // timeout: a large table takes as long as it takes while it moves).
  double stall_timeout_s = 30;

  // Errors name the flag or variable at fault (--storage, --s3-endpoint, AWS_...).
  Status validate() const;
  // Parses `url` (s3://bucket[/prefix]) and takes the credentials and region from the
  // environment (`getenv`, injectable for tests), then validates.
  static Result<S3Params> from_environment(const std::string& url, const std::string& endpoint,
                                           const std::function<const char*(const char*)>& getenv = nullptr);
};

// RFC 3986 percent-encoding as SigV4 wants it: unreserved characters (A-Z a-z 0-9 - . _ ~)
// stay, every other byte becomes %XX (upper-case hex); '/' stays when `keep_slash`.
std::string uri_encode(std::string_view s, bool keep_slash);

// The query string in SigV4 canonical form: names and values encoded, pairs sorted by name
// then value, joined by '&'; a pair with an empty value is "name=".
std::string canonical_query(std::vector<std::pair<std::string, std::string>> params);

// "<prefix>/<kind>/<id>/<file>" (no leading '/' when the prefix is empty); `file` may be empty
// for the resource's own prefix ("<prefix>/<kind>/<id>/") and `id` too for the kind's.
std::string object_key(const std::string& prefix, ResourceKind kind, const std::string& id, const std::string& file);

// endpoint/bucket/encoded-key[?canonical query].
std::string object_url(const S3Params& p, const std::string& key, const std::string& query = {});

// The headers of one request: x-amz-content-sha256 always (the hex SHA-256 of the body, of
// the empty string for bodiless requests), the condition, and x-amz-security-token with a
// session token. Never an empty or removal header (curl would sign it: every request 403).
enum class S3Condition { kNone, kIfNoneMatchAny, kIfMatch };
std::vector<std::string> request_headers(const S3Params& p, const std::string& payload_sha256,
                                         S3Condition condition = S3Condition::kNone, const std::string& etag = {});

// Hex SHA-256 (OpenSSL libcrypto).
std::string sha256_hex(std::span<const uint8_t> bytes);

// One page of a ListObjectsV2 answer.
struct S3ListPage {
  struct Object {
    std::string key;
    double last_modified = 0;  // seconds since the epoch
  };
  std::vector<Object> objects;
  bool truncated = false;
  std::string next_token;  // NextContinuationToken, decoded
};
Result<S3ListPage> parse_list_page(const std::string& xml);

// <Error><Code>..</Code><Message>..</Message></Error>; empty fields when absent.
struct S3ErrorBody {
  std::string code, message;
};
S3ErrorBody parse_error_body(const std::string& xml);

// "2026-12-02T10:00:00.000Z" (XML) and "Wed, 02 Dec 2026 10:00:00 GMT" (HTTP headers), as
// seconds since the epoch; negative when malformed.
double parse_iso8601(const std::string& s);
double parse_http_date(const std::string& s);

}  // namespace solidtex::server
