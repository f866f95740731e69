#include "s3_request.h"

#include <openssl/evp.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <ctime>

namespace solidtex::server {
namespace {

bool unreserved(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '.' ||
         c == '_' || c == '~';
}

// The text of the first <tag>...</tag> at or after `from`, XML entities decoded; `at` gets
// the position after the closing tag (npos when absent).
std::string xml_text(const std::string& xml, const std::string& tag, size_t from, size_t* at = nullptr) {
  const std::string open = "<" + tag + ">", close = "</" + tag + ">";
  const size_t b = xml.find(open, from);
  const size_t e = b == std::string::npos ? b : xml.find(close, b + open.size());
  if (e == std::string::npos) {
    if (at) *at = std::string::npos;
    return {};
  }
  if (at) *at = e + close.size();
  const std::string raw = xml.substr(b + open.size(), e - b - open.size());
  std::string out;
  for (size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] != '&') {
      out += raw[i];
      continue;
    }
    static const std::pair<const char*, char> kEntities[] = {
        {"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
    bool decoded = false;
    for (const auto& [name, c] : kEntities)
      if (raw.compare(i, std::char_traits<char>::length(name), name) == 0) {
        out += c;
        i += std::char_traits<char>::length(name) - 1;
        decoded = true;
        break;
      }
    if (!decoded) out += '&';
  }
  return out;
}

bool valid_bucket(const std::string& b) {
  if (b.size() < 3 || b.size() > 63) return false;
  if (!std::all_of(b.begin(), b.end(), [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '-'; }))
    return false;
  return b.front() != '.' && b.front() != '-' && b.back() != '.' && b.back() != '-';
}

bool valid_prefix(const std::string& p) {
  if (p.empty()) return true;
  if (p.front() == '/' || p.back() == '/' || p.find("//") != std::string::npos) return false;
  if (p == "." || p == ".." || p.find("/./") != std::string::npos || p.find("/../") != std::string::npos ||
      p.rfind("../", 0) == 0 || p.rfind("./", 0) == 0)
    return false;
  return p.size() <= 512 && std::all_of(p.begin(), p.end(), [](char c) { return (unreserved(c) && c != '~') || c == '/'; });
}

}  // namespace

Status S3Params::validate() const {
  const bool http = endpoint.rfind("http://", 0) == 0, https = endpoint.rfind("https://", 0) == 0;
  if (!http && !https) return Status(StatusCode::kInvalidArgument, "must be an http:// or https:// URL", "--s3-endpoint");
  const std::string host = endpoint.substr(http ? 7 : 8);
  if (host.empty() || host.find('/') != std::string::npos || host.find('?') != std::string::npos)
    return Status(StatusCode::kInvalidArgument, "must be scheme://host[:port] without a path (path-style requests add the bucket)",
                  "--s3-endpoint");
  if (!valid_bucket(bucket))
    return Status(StatusCode::kInvalidArgument,
                  "bucket '" + bucket + "' is not a valid bucket name (3-63 of a-z 0-9 . -)", "--storage");
  if (!valid_prefix(prefix))
    return Status(StatusCode::kInvalidArgument,
                  "prefix '" + prefix + "' must be segments of A-Z a-z 0-9 . _ - separated by single '/'", "--storage");
  if (region.empty() || !std::all_of(region.begin(), region.end(), [](char c) { return unreserved(c); }))
    return Status(StatusCode::kInvalidArgument, "must be a region name such as us-east-1", "AWS_REGION");
  if (access_key.empty())
    return Status(StatusCode::kInvalidArgument, "must be set (the S3 access key) for --storage s3://", "AWS_ACCESS_KEY_ID");
  if (access_key.find(':') != std::string::npos || access_key.find('\n') != std::string::npos)
    return Status(StatusCode::kInvalidArgument, "must not contain ':' or a newline", "AWS_ACCESS_KEY_ID");
  if (secret_key.empty())
    return Status(StatusCode::kInvalidArgument, "must be set (the S3 secret key) for --storage s3://", "AWS_SECRET_ACCESS_KEY");
  if (session_token.find_first_of("\r\n") != std::string::npos)
    return Status(StatusCode::kInvalidArgument, "must not contain a newline", "AWS_SESSION_TOKEN");
  if (!(connect_timeout_s > 0 && connect_timeout_s <= 600))
    return Status(StatusCode::kInvalidArgument, "must be in (0, 600] seconds", "connect_timeout_s");
  if (!(stall_timeout_s > 0 && stall_timeout_s <= 3600))
    return Status(StatusCode::kInvalidArgument, "must be in (0, 3600] seconds", "stall_timeout_s");
  return Status::ok();
}

Result<S3Params> S3Params::from_environment(const std::string& url, const std::string& endpoint,
                                            const std::function<const char*(const char*)>& getenv) {
  auto env = [&](const char* name) -> std::string {
    const char* v = getenv ? getenv(name) : std::getenv(name);
    return v ? std::string(v) : std::string();
  };
  if (url.rfind("s3://", 0) != 0)
    return Status(StatusCode::kInvalidArgument, "must be s3://bucket[/prefix] (or leave it out and use --data DIR)", "--storage");
  if (endpoint.empty())
    return Status(StatusCode::kInvalidArgument, "is required with --storage s3:// (e.g. http://127.0.0.1:7070)",
                  "--s3-endpoint");
  S3Params p;
  std::string rest = url.substr(5);
  while (!rest.empty() && rest.back() == '/') rest.pop_back();
  const size_t slash = rest.find('/');
  p.bucket = rest.substr(0, slash);
  p.prefix = slash == std::string::npos ? "" : rest.substr(slash + 1);
  p.endpoint = endpoint;
  while (!p.endpoint.empty() && p.endpoint.back() == '/') p.endpoint.pop_back();
  if (const std::string r = env("AWS_REGION"); !r.empty()) p.region = r;
  p.access_key = env("AWS_ACCESS_KEY_ID");
  p.secret_key = env("AWS_SECRET_ACCESS_KEY");
  p.session_token = env("AWS_SESSION_TOKEN");
  SOLIDTEX_RETURN_IF_ERROR(p.validate());
  return p;
}

std::string uri_encode(std::string_view s, bool keep_slash) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  out.reserve(s.size());
  for (char ch : s) {
    if (unreserved(ch) || (keep_slash && ch == '/')) {
      out += ch;
    } else {
      const auto c = static_cast<unsigned char>(ch);
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

std::string canonical_query(std::vector<std::pair<std::string, std::string>> params) {
  for (auto& [k, v] : params) {
    k = uri_encode(k, false);
    v = uri_encode(v, false);
  }
  std::sort(params.begin(), params.end());
  std::string out;
  for (const auto& [k, v] : params) {
    if (!out.empty()) out += '&';
    out += k + "=" + v;
  }
  return out;
}

std::string object_key(const std::string& prefix, ResourceKind kind, const std::string& id, const std::string& file) {
  std::string key = prefix.empty() ? std::string() : prefix + "/";
  key += kind_dir(kind);
  key += "/";
  if (!id.empty()) key += id + "/" + file;
  return key;
}

std::string object_url(const S3Params& p, const std::string& key, const std::string& query) {
  std::string url = p.endpoint + "/" + p.bucket + "/" + uri_encode(key, true);
  if (!query.empty()) url += "?" + query;
  return url;
}

std::vector<std::string> request_headers(const S3Params& p, const std::string& payload_sha256, S3Condition condition,
                                         const std::string& etag) {
  std::vector<std::string> h;
  h.push_back("x-amz-content-sha256: " + payload_sha256);
  if (condition == S3Condition::kIfNoneMatchAny) h.push_back("If-None-Match: *");
  if (condition == S3Condition::kIfMatch) h.push_back("If-Match: " + etag);
  if (!p.session_token.empty()) h.push_back("x-amz-security-token: " + p.session_token);
  return h;
}

std::string sha256_hex(std::span<const uint8_t> bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  EVP_Digest(bytes.data(), bytes.size(), digest, &n, EVP_sha256(), nullptr);
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < n; ++i) {
    out += hex[digest[i] >> 4];
    out += hex[digest[i] & 15];
  }
  return out;
}

Result<S3ListPage> parse_list_page(const std::string& xml) {
  if (xml.find("<ListBucketResult") == std::string::npos)
    return Status(StatusCode::kCorrupt, "not a ListObjectsV2 answer: " + xml.substr(0, 200));
  S3ListPage page;
  size_t at = 0;
  for (;;) {
    size_t end = 0;
    const std::string contents = xml_text(xml, "Contents", at, &end);
    if (end == std::string::npos) break;
    S3ListPage::Object o;
    o.key = xml_text(contents, "Key", 0);
    o.last_modified = parse_iso8601(xml_text(contents, "LastModified", 0));
    page.objects.push_back(std::move(o));
    at = end;
  }
  page.truncated = xml_text(xml, "IsTruncated", 0) == "true";
  page.next_token = xml_text(xml, "NextContinuationToken", 0);
  if (page.truncated && page.next_token.empty())
    return Status(StatusCode::kCorrupt, "a truncated ListObjectsV2 answer without NextContinuationToken");
  return page;
}

S3ErrorBody parse_error_body(const std::string& xml) {
  return {xml_text(xml, "Code", 0), xml_text(xml, "Message", 0)};
}

double parse_iso8601(const std::string& s) {
  std::tm tm{};
  double frac = 0;
  int n = 0;
  if (std::sscanf(s.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d%n", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour, &tm.tm_min,
                  &tm.tm_sec, &n) != 6)
    return -1;
  if (s.size() > size_t(n) && s[size_t(n)] == '.') frac = std::strtod(s.c_str() + n, nullptr);  // ".500Z" -> 0.5
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return double(timegm(&tm)) + frac;
}

double parse_http_date(const std::string& s) {
  std::tm tm{};
  const char* end = strptime(s.c_str(), "%a, %d %b %Y %H:%M:%S", &tm);
  if (!end) return -1;
  return double(timegm(&tm));
}

}  // namespace solidtex::server
