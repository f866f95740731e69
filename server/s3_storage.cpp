#include "s3_storage.h"

#include <curl/curl.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <mutex>
#include <thread>

namespace solidtex::server {
namespace {

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\r' || s.back() == '\n' || s.back() == ' ' || s.back() == '\t')) s.pop_back();
  size_t b = 0;
  while (b < s.size() && (s[b] == ' ' || s[b] == '\t')) ++b;
  return s.substr(b);
}

struct Request {
  const char* method = "GET";  // GET, HEAD, PUT, DELETE
  std::string key;
  std::string query;  // canonical (s3_request.h)
  std::span<const uint8_t> body;
  S3Condition condition = S3Condition::kNone;
  std::string etag;
  int64_t max_body = int64_t(64) << 20;  // of a 2xx answer's body; beyond: kTooLarge
  bool range_first_byte = false;          // Range: bytes=0-0
  bool idempotent() const { return condition == S3Condition::kNone; }
};

struct Response {
  long status = 0;
  std::vector<uint8_t> body;
  std::string etag, last_modified, date;
  int64_t content_length = -1;
  bool too_large = false;
  std::string body_text() const { return std::string(body.begin(), body.end()); }
  // The object's age by the server's clock (0 when the headers are missing).
  double age_seconds() const {
    const double now = parse_http_date(date), then = parse_http_date(last_modified);
    return now >= 0 && then >= 0 ? std::max(0.0, now - then) : 0.0;
  }
};

// State the curl callbacks of one transfer share.
struct Transfer {
  Response* response;
  int64_t max_body;
  std::span<const uint8_t> upload;
  size_t uploaded = 0;
};

size_t on_header(char* data, size_t size, size_t n, void* user) {
  auto* t = static_cast<Transfer*>(user);
  const std::string line(data, size * n);
  if (line.rfind("HTTP/", 0) == 0) {  // a new status line (after a 100 Continue, too)
    const size_t sp = line.find(' ');
    t->response->status = sp == std::string::npos ? 0 : std::atol(line.c_str() + sp + 1);
    return size * n;
  }
  const size_t colon = line.find(':');
  if (colon == std::string::npos) return size * n;
  const std::string name = lower(line.substr(0, colon)), value = trim(line.substr(colon + 1));
  if (name == "etag") t->response->etag = value;
  else if (name == "last-modified") t->response->last_modified = value;
  else if (name == "date") t->response->date = value;
  else if (name == "content-length") t->response->content_length = std::atoll(value.c_str());
  return size * n;
}

size_t on_body(char* data, size_t size, size_t n, void* user) {
  auto* t = static_cast<Transfer*>(user);
  Response& r = *t->response;
  // Error answers are small XML documents; a successful one is bounded by the caller.
  const int64_t limit = r.status >= 200 && r.status < 300 ? t->max_body : int64_t(1) << 20;
  if (r.body.empty() && r.content_length > 0 && r.content_length <= limit) r.body.reserve(size_t(r.content_length));
  if (r.content_length > limit || int64_t(r.body.size() + size * n) > limit) {
    r.too_large = true;
    return 0;  // curl stops the transfer: CURLE_WRITE_ERROR
  }
  r.body.insert(r.body.end(), data, data + size * n);
  return size * n;
}

size_t on_read(char* buffer, size_t size, size_t n, void* user) {
  auto* t = static_cast<Transfer*>(user);
  const size_t k = std::min(size * n, t->upload.size() - t->uploaded);
  std::copy_n(t->upload.data() + t->uploaded, k, buffer);
  t->uploaded += k;
  return k;
}

// curl rewinds the body when it must send it again (a redirect, a retried connection).
int on_seek(void* user, curl_off_t offset, int origin) {
  auto* t = static_cast<Transfer*>(user);
  if (origin != SEEK_SET || offset < 0 || size_t(offset) > t->upload.size()) return CURL_SEEKFUNC_FAIL;
  t->uploaded = size_t(offset);
  return CURL_SEEKFUNC_OK;
}

}  // namespace

struct S3Storage::Impl {
  S3Params params;
  std::string sigv4;  // "aws:amz:<region>:s3"
  mutable std::mutex pool_mutex;
  mutable std::vector<CURL*> pool;  // idle handles: their connections stay open for reuse

  explicit Impl(S3Params p) : params(std::move(p)), sigv4("aws:amz:" + params.region + ":s3") {}
  ~Impl() {
    for (CURL* h : pool) curl_easy_cleanup(h);
  }

  std::string where() const { return "s3://" + params.bucket + (params.prefix.empty() ? "" : "/" + params.prefix) + " at " + params.endpoint; }

  CURL* acquire() const {
    {
      std::lock_guard<std::mutex> g(pool_mutex);
      if (!pool.empty()) {
        CURL* h = pool.back();
        pool.pop_back();
        curl_easy_reset(h);  // options go; the connection cache stays
        return h;
      }
    }
    return curl_easy_init();
  }
  void give_back(CURL* h) const {
    std::lock_guard<std::mutex> g(pool_mutex);
    if (pool.size() < 16) pool.push_back(h);
    else curl_easy_cleanup(h);
  }

  Result<Response> perform_once(const Request& rq) const {
    CURL* h = acquire();
    if (!h) return Status(StatusCode::kInternal, "curl_easy_init failed");
    Response response;
    Transfer t{&response, rq.max_body, rq.body, 0};
    const std::string url = object_url(params, rq.key, rq.query);
    const std::string method = rq.method;
    const std::string payload = sha256_hex(rq.body);
    curl_slist* headers = nullptr;
    for (const std::string& line : request_headers(params, payload, rq.condition, rq.etag))
      headers = curl_slist_append(headers, line.c_str());
    if (rq.range_first_byte) headers = curl_slist_append(headers, "Range: bytes=0-0");
    char error[CURL_ERROR_SIZE] = {0};
    curl_easy_setopt(h, CURLOPT_URL, url.c_str());
    curl_easy_setopt(h, CURLOPT_AWS_SIGV4, sigv4.c_str());
    curl_easy_setopt(h, CURLOPT_USERNAME, params.access_key.c_str());
    curl_easy_setopt(h, CURLOPT_PASSWORD, params.secret_key.c_str());
    curl_easy_setopt(h, CURLOPT_HTTPHEADER, headers);
    curl_easy_setopt(h, CURLOPT_NOSIGNAL, 1L);  // threads: no SIGALRM for DNS timeouts
    curl_easy_setopt(h, CURLOPT_ERRORBUFFER, error);
    curl_easy_setopt(h, CURLOPT_CONNECTTIMEOUT_MS, long(params.connect_timeout_s * 1000));
    curl_easy_setopt(h, CURLOPT_LOW_SPEED_LIMIT, 1024L);
    curl_easy_setopt(h, CURLOPT_LOW_SPEED_TIME, long(std::max(1.0, params.stall_timeout_s)));
    curl_easy_setopt(h, CURLOPT_HEADERFUNCTION, on_header);
    curl_easy_setopt(h, CURLOPT_HEADERDATA, &t);
    curl_easy_setopt(h, CURLOPT_WRITEFUNCTION, on_body);
    curl_easy_setopt(h, CURLOPT_WRITEDATA, &t);
    if (method == "PUT") {
      curl_easy_setopt(h, CURLOPT_UPLOAD, 1L);
      curl_easy_setopt(h, CURLOPT_READFUNCTION, on_read);
      curl_easy_setopt(h, CURLOPT_READDATA, &t);
      curl_easy_setopt(h, CURLOPT_SEEKFUNCTION, on_seek);
      curl_easy_setopt(h, CURLOPT_SEEKDATA, &t);
      curl_easy_setopt(h, CURLOPT_INFILESIZE_LARGE, curl_off_t(rq.body.size()));
    } else if (method == "HEAD") {
      curl_easy_setopt(h, CURLOPT_NOBODY, 1L);
    } else if (method == "DELETE") {
      curl_easy_setopt(h, CURLOPT_CUSTOMREQUEST, "DELETE");
    }
    const CURLcode rc = curl_easy_perform(h);
    curl_slist_free_all(headers);
    give_back(h);
    if (response.too_large)
      return Status(StatusCode::kTooLarge, "s3 object '" + rq.key + "' is larger than " + std::to_string(rq.max_body) + " bytes");
    if (rc != CURLE_OK)
      return Status(StatusCode::kUnavailable, "storage unavailable: cannot reach the S3 endpoint " + params.endpoint +
                                                        " (" + method + " " + rq.key + "): " +
                                                        (error[0] ? std::string(error) : curl_easy_strerror(rc)));
    return response;
  }

  // perform_once, retried twice (after 50 and 200 ms) for idempotent requests that failed in
  // transport or with a 5xx.
  Result<Response> perform(const Request& rq) const {
    for (int attempt = 0;; ++attempt) {
      auto r = perform_once(rq);
      const bool transient = r ? r->status >= 500 : r.status().code() == StatusCode::kUnavailable;
      if (!transient || !rq.idempotent() || attempt == 2) return r;
      std::this_thread::sleep_for(std::chrono::milliseconds(attempt == 0 ? 50 : 200));
    }
  }

  // The Status of an answer the caller did not expect.
  Status failure(const Response& r, const Request& rq) const {
    const S3ErrorBody e = parse_error_body(r.body_text());
    const std::string said = std::to_string(r.status) + (e.code.empty() ? "" : " " + e.code) +
                             (e.message.empty() ? "" : ": " + e.message);
    const std::string what = std::string(rq.method) + " " + rq.key;
    // By code too: versitygw answers an unknown access key 404 XAdminUserNotFound, AWS 403.
    static const char* kCredentialCodes[] = {"InvalidAccessKeyId", "SignatureDoesNotMatch", "XAdminUserNotFound",
                                             "AccessDenied", "ExpiredToken", "InvalidToken", "RequestTimeTooSkewed"};
    const bool credentials = std::find(std::begin(kCredentialCodes), std::end(kCredentialCodes), e.code) !=
                             std::end(kCredentialCodes);
    if (e.code == "RequestTimeTooSkewed")
      return Status(StatusCode::kUnavailable,
                    "storage unavailable: " + where() + " says this host's clock is off by more than 15 minutes (" + said + ")");
    if (r.status == 403 || r.status == 401 || credentials)
      return Status(StatusCode::kUnavailable,
                    "storage unavailable: " + where() + " refused the credentials (" + said + ", " + what +
                        "): check AWS_ACCESS_KEY_ID, AWS_SECRET_ACCESS_KEY and AWS_REGION");
    if (e.code == "NoSuchBucket")
      return Status(StatusCode::kUnavailable,
                    "storage unavailable: bucket '" + params.bucket + "' does not exist at " + params.endpoint);
    if (r.status == 404) return Status(StatusCode::kNotFound, "no object '" + rq.key + "' in " + where());
    if (r.status >= 500 || r.status == 429)
      return Status(StatusCode::kUnavailable, "storage unavailable: " + where() + " answered " + said + " (" + what + ")");
    return Status(StatusCode::kInternal, where() + " refused " + what + ": " + said);
  }

  std::string key(ResourceKind kind, const std::string& id, const std::string& file) const {
    return object_key(params.prefix, kind, id, file);
  }

  // Every object under `prefix`, every page; `date` gets the server's Date of the last page.
  Result<std::vector<S3ListPage::Object>> list(const std::string& prefix, std::string* date = nullptr) const {
    std::vector<S3ListPage::Object> out;
    std::string token;
    for (;;) {
      std::vector<std::pair<std::string, std::string>> q{{"list-type", "2"}, {"prefix", prefix}};
      if (!token.empty()) q.emplace_back("continuation-token", token);
      Request rq;
      rq.query = canonical_query(q);
      SOLIDTEX_ASSIGN_OR_RETURN(Response r, perform(rq));
      if (r.status != 200) return failure(r, rq);
      SOLIDTEX_ASSIGN_OR_RETURN(S3ListPage page, parse_list_page(r.body_text()));
      if (date) *date = r.date;
      for (auto& o : page.objects) out.push_back(std::move(o));
      if (!page.truncated) return out;
      token = page.next_token;
    }
  }

  Result<std::string> put(ResourceKind kind, const std::string& id, const std::string& file, std::span<const uint8_t> bytes,
                          S3Condition condition, const std::string& etag) {
    if (!valid_id(id)) return Status(StatusCode::kInvalidArgument, "malformed id '" + id + "'", "id");
    Request rq;
    rq.method = "PUT";
    rq.key = key(kind, id, file);
    rq.body = bytes;
    rq.condition = condition;
    rq.etag = etag;
    SOLIDTEX_ASSIGN_OR_RETURN(Response r, perform(rq));
    const bool gone = r.status == 404 && parse_error_body(r.body_text()).code != "NoSuchBucket";
    const bool lost = r.status == 412 || r.status == 409 || (condition == S3Condition::kIfMatch && gone);
    if (lost && condition == S3Condition::kIfNoneMatchAny)
      return Status(StatusCode::kAlreadyExists, "'" + rq.key + "' exists");
    if (lost && condition == S3Condition::kIfMatch)
      return Status(StatusCode::kFailedPrecondition, "'" + rq.key + "' was changed by another writer");
    if (r.status != 200) return failure(r, rq);
    if (!r.etag.empty()) return r.etag;
    // A server that does not echo the ETag: ask for it (only conditional callers use it).
    Request head;
    head.method = "HEAD";
    head.key = rq.key;
    SOLIDTEX_ASSIGN_OR_RETURN(Response h, perform(head));
    if (h.status != 200) return failure(h, head);
    return h.etag;
  }

  Status delete_key(const std::string& k, S3Condition condition, const std::string& etag) const {
    Request rq;
    rq.method = "DELETE";
    rq.key = k;
    rq.condition = condition;
    rq.etag = etag;
    SOLIDTEX_ASSIGN_OR_RETURN(Response r, perform(rq));
    if (r.status == 204 || r.status == 200) return Status::ok();
    if (r.status == 412 || r.status == 409)
      return Status(StatusCode::kFailedPrecondition, "'" + k + "' was changed by another writer");
    return failure(r, rq);
  }

  Result<Response> get(ResourceKind kind, const std::string& id, const std::string& file, int64_t max_bytes) const {
    if (!valid_id(id)) return Status(StatusCode::kNotFound, "no such resource '" + id + "'", "id");
    Request rq;
    rq.key = key(kind, id, file);
    rq.max_body = max_bytes;
    SOLIDTEX_ASSIGN_OR_RETURN(Response r, perform(rq));
    if (r.status != 200) return failure(r, rq);
    return r;
  }
};

S3Storage::S3Storage(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
S3Storage::~S3Storage() = default;

Result<std::unique_ptr<S3Storage>> S3Storage::open(const S3Params& params, std::vector<std::string>* report,
                                                   double grace_seconds) {
  SOLIDTEX_RETURN_IF_ERROR(params.validate());
  static std::once_flag curl_ready;
  static CURLcode global = CURLE_OK;
  std::call_once(curl_ready, [] { global = curl_global_init(CURL_GLOBAL_DEFAULT); });
  if (global != CURLE_OK) return Status(StatusCode::kInternal, std::string("curl_global_init: ") + curl_easy_strerror(global));
  std::unique_ptr<S3Storage> store(new S3Storage(std::make_unique<Impl>(params)));
  const Impl& s = *store->impl_;
  for (ResourceKind kind : {ResourceKind::kExemplar, ResourceKind::kField, ResourceKind::kVolume, ResourceKind::kMesh}) {
    const std::string prefix = object_key(params.prefix, kind, "", "");
    std::string date;
    auto listed = s.list(prefix, &date);
    if (!listed) return Status(listed.status().code(), "cannot use --storage " + s.where() + ": " + listed.status().message(), "--storage");
    // Group by resource: its newest object's age, and whether it is acknowledged.
    struct Seen {
      double newest = 0;
      bool acknowledged = false;
      std::vector<std::string> keys;
    };
    std::map<std::string, Seen> resources;
    for (const auto& o : *listed) {
      const std::string rest = o.key.substr(prefix.size());
      const size_t slash = rest.find('/');
      if (slash == std::string::npos) continue;  // not ours: left alone
      Seen& r = resources[rest.substr(0, slash)];
      r.newest = std::max(r.newest, o.last_modified);
      r.acknowledged = r.acknowledged || rest.substr(slash + 1) == acknowledging_file(kind);
      r.keys.push_back(o.key);
    }
    const double now = parse_http_date(date);
    for (auto& [id, r] : resources) {
      if (r.acknowledged) continue;
      const double age = now >= 0 ? now - r.newest : 0;
      if (age < grace_seconds) {
        if (report)
          report->push_back("skipped young leftover " + prefix + id + "/ (modified within " + std::to_string(int(grace_seconds)) +
                            " s: another replica may be writing it)");
        continue;
      }
      for (const std::string& k : r.keys) (void)s.delete_key(k, S3Condition::kNone, {});
      if (report) report->push_back("removed half-written leftover " + prefix + id + "/");
    }
  }
  return store;
}

std::string S3Storage::describe() const { return impl_->where(); }

Status S3Storage::create(ResourceKind, const std::string& id) {
  if (!valid_id(id)) return Status(StatusCode::kInvalidArgument, "malformed id '" + id + "'", "id");
  return Status::ok();  // keys need no directory
}

Status S3Storage::write(ResourceKind kind, const std::string& id, const std::string& file, std::span<const uint8_t> bytes) {
  return impl_->put(kind, id, file, bytes, S3Condition::kNone, {}).status();
}

Result<std::string> S3Storage::create_new(ResourceKind kind, const std::string& id, const std::string& file,
                                          std::span<const uint8_t> bytes) {
  return impl_->put(kind, id, file, bytes, S3Condition::kIfNoneMatchAny, {});
}

Result<std::string> S3Storage::replace_if_match(ResourceKind kind, const std::string& id, const std::string& file,
                                                std::span<const uint8_t> bytes, const std::string& etag) {
  return impl_->put(kind, id, file, bytes, S3Condition::kIfMatch, etag);
}

Status S3Storage::remove_if_match(ResourceKind kind, const std::string& id, const std::string& file, const std::string& etag) {
  if (!valid_id(id)) return Status(StatusCode::kNotFound, "no such resource '" + id + "'", "id");
  return impl_->delete_key(impl_->key(kind, id, file), S3Condition::kIfMatch, etag);
}

Result<std::vector<uint8_t>> S3Storage::read(ResourceKind kind, const std::string& id, const std::string& file,
                                             int64_t max_bytes) const {
  SOLIDTEX_ASSIGN_OR_RETURN(Response r, impl_->get(kind, id, file, max_bytes));
  return std::move(r.body);
}

Result<VersionedObject> S3Storage::read_versioned(ResourceKind kind, const std::string& id, const std::string& file,
                                                  int64_t max_bytes) const {
  SOLIDTEX_ASSIGN_OR_RETURN(Response r, impl_->get(kind, id, file, max_bytes));
  VersionedObject out;
  out.age_seconds = r.age_seconds();
  out.etag = r.etag;
  out.bytes = std::move(r.body);
  return out;
}

Result<bool> S3Storage::exists(ResourceKind kind, const std::string& id, const std::string& file) const {
  if (!valid_id(id)) return false;
  // A one-byte ranged GET rather than HEAD: a HEAD's 404 has no body, so a missing key and a
  // missing bucket (a misconfigured or vanished store, which must not look like "deleted")
  // could not be told apart.
  Request rq;
  rq.key = impl_->key(kind, id, file);
  rq.range_first_byte = true;
  rq.max_body = 1 << 16;
  auto r = impl_->perform(rq);
  if (!r && r.status().code() == StatusCode::kTooLarge) return true;  // a server that ignored the range
  if (!r) return r.status();
  if (r->status == 200 || r->status == 206 || r->status == 416) return true;  // 416: an empty object
  if (r->status == 404 && parse_error_body(r->body_text()).code != "NoSuchBucket") return false;
  return impl_->failure(*r, rq);
}

Result<std::vector<std::string>> S3Storage::files(ResourceKind kind, const std::string& id) const {
  std::vector<std::string> out;
  if (!valid_id(id)) return out;
  const std::string prefix = impl_->key(kind, id, "");
  SOLIDTEX_ASSIGN_OR_RETURN(auto objects, impl_->list(prefix));
  for (const auto& o : objects) {
    const std::string name = o.key.substr(prefix.size());
    if (!name.empty() && name.find('/') == std::string::npos) out.push_back(name);
  }
  std::sort(out.begin(), out.end());
  return out;
}

Result<std::vector<std::string>> S3Storage::ids(ResourceKind kind) const {
  const std::string prefix = object_key(impl_->params.prefix, kind, "", "");
  const std::string ack = std::string("/") + acknowledging_file(kind);
  SOLIDTEX_ASSIGN_OR_RETURN(auto objects, impl_->list(prefix));
  std::vector<std::string> out;
  for (const auto& o : objects) {
    const std::string rest = o.key.substr(prefix.size());
    if (rest.size() > ack.size() && rest.ends_with(ack)) {
      const std::string id = rest.substr(0, rest.size() - ack.size());
      if (valid_id(id)) out.push_back(id);
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

Status S3Storage::remove(ResourceKind kind, const std::string& id) {
  if (!valid_id(id)) return Status(StatusCode::kNotFound, "no such resource '" + id + "'", "id");
  // Unacknowledged first: from here on no replica sees the resource, whatever happens next
  // (a crash leaves a leftover the next open() removes).
  SOLIDTEX_RETURN_IF_ERROR(impl_->delete_key(impl_->key(kind, id, acknowledging_file(kind)), S3Condition::kNone, {}));
  SOLIDTEX_ASSIGN_OR_RETURN(auto names, files(kind, id));
  for (const std::string& name : names)
    SOLIDTEX_RETURN_IF_ERROR(impl_->delete_key(impl_->key(kind, id, name), S3Condition::kNone, {}));
  return Status::ok();
}

}  // namespace solidtex::server
