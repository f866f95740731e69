// The S3-compatible Storage backend (storage.h): `solidtex serve --storage s3://bucket/prefix
// --s3-endpoint URL`, credentials from AWS_ACCESS_KEY_ID / AWS_SECRET_ACCESS_KEY / AWS_REGION
// (default us-east-1) / AWS_SESSION_TOKEN. Keys mirror the local layout (data_store.h) under
// the prefix: <prefix>/<kind>/<id>/<file>. Path-style URLs (endpoint/bucket/key), so any
// S3-compatible server works without wildcard DNS.
//
// Requests are signed by libcurl's CURLOPT_AWS_SIGV4 (README, "Storage backends": libs3 signs
// SigV2 only and has no conditional headers; the AWS SDK is not packaged for Debian 12), with
// the request parts curl gets wrong built by s3_request.h. Mapping of the Storage operations:
//   write              PUT (replaces)
//   create_new         PUT If-None-Match: *   412 (or 409 ConditionalRequestConflict): kAlreadyExists
//   replace_if_match   PUT If-Match: etag     412 / 409 / 404: kFailedPrecondition
//   remove_if_match    DELETE If-Match: etag  412 / 409: kFailedPrecondition (a missing key: ok)
//   read, read_versioned  GET (the size checked against the limit from Content-Length first)
//   exists             GET Range: bytes=0-0 (a HEAD's 404 cannot tell a missing bucket)
//   files, ids         ListObjectsV2, every page (ids: keys ending in the acknowledging file)
//   remove             DELETE the acknowledging file, then every other key of the resource
// Durability: an object is stored once the server answered 200. Ages (read_versioned, the
// leftover rule of open()) are measured by the server's clock: its Date header minus the
// object's Last-Modified, so replicas' clocks do not enter them.
// Failures: an unreachable endpoint, a timeout, 5xx, or a refusal of the credentials (403)
// are kUnavailable, naming the endpoint and what went wrong (502 to clients); other
// unexpected answers are kInternal. Idempotent requests (GET, HEAD, LIST, unconditional PUT
// and DELETE) are retried twice after a transport error or a 5xx; conditional ones are not
// (a retry of a request that did succeed would report a lost race).
// Memory: a GET holds the object once (bounded by the caller's max_bytes); a PUT streams the
// caller's buffer. Thread-safe: each request uses its own connection handle from a pool that
// keeps connections alive between requests.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "s3_request.h"
#include "storage.h"

namespace solidtex::server {

class S3Storage : public Storage {
 public:
  // Checks the endpoint, bucket and credentials with one listing (errors naming what is
  // wrong: cannot connect, unknown bucket, credentials refused), then removes leftovers:
  // resources without their acknowledging file whose newest object is older than
  // `grace_seconds` (younger ones may be another replica's upload in progress).
  static Result<std::unique_ptr<S3Storage>> open(const S3Params& params, std::vector<std::string>* report,
                                                 double grace_seconds = kLeftoverGraceSeconds);
  ~S3Storage() override;

  std::string describe() const override;
  Status create(ResourceKind kind, const std::string& id) override;
  Status write(ResourceKind kind, const std::string& id, const std::string& file,
               std::span<const uint8_t> bytes) override;
  Result<std::string> create_new(ResourceKind kind, const std::string& id, const std::string& file,
                                 std::span<const uint8_t> bytes) override;
  Result<std::string> replace_if_match(ResourceKind kind, const std::string& id, const std::string& file,
                                       std::span<const uint8_t> bytes, const std::string& etag) override;
  Status remove_if_match(ResourceKind kind, const std::string& id, const std::string& file,
                         const std::string& etag) override;
  Result<std::vector<uint8_t>> read(ResourceKind kind, const std::string& id, const std::string& file,
                                    int64_t max_bytes = int64_t(1) << 32) const override;
  Result<VersionedObject> read_versioned(ResourceKind kind, const std::string& id, const std::string& file,
                                         int64_t max_bytes = int64_t(1) << 20) const override;
  Result<bool> exists(ResourceKind kind, const std::string& id, const std::string& file) const override;
  Result<std::vector<std::string>> files(ResourceKind kind, const std::string& id) const override;
  Result<std::vector<std::string>> ids(ResourceKind kind) const override;
  Status remove(ResourceKind kind, const std::string& id) override;

  struct Impl;

 private:
  explicit S3Storage(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace solidtex::server
