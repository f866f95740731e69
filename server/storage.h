// Where the service keeps everything it acknowledges: the operations the services need, with
// two backends (README, "Storage backends"): DataStore, a local directory (data_store.h, the
// default, also correct on a shared file system), and S3Storage, an S3-compatible object store
// (s3_storage.h). Objects are addressed by (kind, resource id, file name); both backends use
// the same relative layout, <kind>/<id>/<file> (data_store.h lists the files of each kind).
//
// Contract, for every backend:
// - Durability: an operation that returned ok has reached the store (fsync'd, or answered 200
//   by the object store); a kill -9 of the caller afterwards loses nothing.
// - Writes are whole: a reader sees an object's previous content or its new content, never a
//   part. A resource's acknowledging file (acknowledging_file) is written last and removed
//   first, so a resource is either acknowledged and complete or invisible.
// - Several replicas may use one store at once. Visibility is read-after-write: once a write
//   returned ok in one replica, reads in every replica see it.
// - Conditional operations are atomic across replicas: of any number of concurrent
//   create_new() calls on one object exactly one succeeds; of concurrent replace_if_match()
//   calls with the same etag at most one succeeds. An etag names one written content of an
//   object (a content hash), and is what those calls compare.
// - Errors are values. kNotFound: no such object. kAlreadyExists / kFailedPrecondition: a
//   condition did not hold (the race was lost). kUnavailable: the store cannot be
//   reached or refuses service right now (answered 502, "retry later", by http_errors.cpp).
//   Other codes (kIo, kInternal, kTooLarge) are failures of this request.
// Implementations are thread-safe.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/status.h"

namespace solidtex::server {

enum class ResourceKind { kExemplar, kField, kVolume, kMesh };

// The directory (local) or key segment (S3) of a kind: "exemplars", "fields", ...
const char* kind_dir(ResourceKind kind);

// The file whose presence acknowledges a resource of that kind.
const char* acknowledging_file(ResourceKind kind);

// Age (newest modification of a resource's objects) below which a leftover, a resource
// without its acknowledging file, is left alone when a backend opens: another replica may be
// writing it right now. Uploads and deletes finish well within it.
constexpr double kLeftoverGraceSeconds = 600;

// What a conditional read returns: the content, the etag to pass to replace_if_match() or
// remove_if_match(), and how long ago the content was written (by the store's clock for S3).
struct VersionedObject {
  std::vector<uint8_t> bytes;
  std::string etag;
  double age_seconds = 0;
};

class Storage {
 public:
  virtual ~Storage() = default;

  // For logs: the directory, or s3://bucket/prefix at the endpoint.
  virtual std::string describe() const = 0;

  // Prepares resource `id` for writes (local: its directory). kInvalidArgument for a malformed id.
  virtual Status create(ResourceKind kind, const std::string& id) = 0;
  // Writes the object, replacing any previous content.
  virtual Status write(ResourceKind kind, const std::string& id, const std::string& file,
                       std::span<const uint8_t> bytes) = 0;
  // Writes the object only if it does not exist (write-once objects, acknowledgements, claims):
  // kAlreadyExists, with nothing changed, when it does. Returns the new etag.
  virtual Result<std::string> create_new(ResourceKind kind, const std::string& id, const std::string& file,
                                         std::span<const uint8_t> bytes) = 0;
  // Replaces the object only if its current etag is `etag`: kFailedPrecondition, nothing
  // changed, when it is not (another writer came first) or the object is gone. Returns the new etag.
  virtual Result<std::string> replace_if_match(ResourceKind kind, const std::string& id, const std::string& file,
                                               std::span<const uint8_t> bytes, const std::string& etag) = 0;
  // Removes the object only if its current etag is `etag`: kFailedPrecondition when it is
  // another. When it is gone: kNotFound from the local store, ok from S3 (which answers a
  // DELETE of a missing key with success, conditions or not).
  virtual Status remove_if_match(ResourceKind kind, const std::string& id, const std::string& file,
                                 const std::string& etag) = 0;

  // The object's bytes; kTooLarge beyond `max_bytes` (checked before reading it all).
  virtual Result<std::vector<uint8_t>> read(ResourceKind kind, const std::string& id, const std::string& file,
                                            int64_t max_bytes = int64_t(1) << 32) const = 0;
  // The object with its etag and age (leases, revision claims).
  virtual Result<VersionedObject> read_versioned(ResourceKind kind, const std::string& id, const std::string& file,
                                                 int64_t max_bytes = int64_t(1) << 20) const = 0;
  // Whether the object exists (false for a malformed id).
  virtual Result<bool> exists(ResourceKind kind, const std::string& id, const std::string& file) const = 0;
  // Files of one resource, sorted (none: an empty list).
  virtual Result<std::vector<std::string>> files(ResourceKind kind, const std::string& id) const = 0;
  // Ids of the acknowledged resources of a kind, sorted.
  virtual Result<std::vector<std::string>> ids(ResourceKind kind) const = 0;
  // Removes the resource: its acknowledging file first (it is then gone for every replica),
  // then the rest. kNotFound for a malformed id.
  virtual Status remove(ResourceKind kind, const std::string& id) = 0;

  // Helpers over the operations above.
  Status write_text(ResourceKind kind, const std::string& id, const std::string& file, const std::string& text);
  Result<std::string> create_new_text(ResourceKind kind, const std::string& id, const std::string& file,
                                      const std::string& text);
  Result<std::string> read_text(ResourceKind kind, const std::string& id, const std::string& file) const;
  // The resource is acknowledged: written completely, possibly by another replica, not deleted.
  Result<bool> acknowledged(ResourceKind kind, const std::string& id) const;

  // A fresh opaque id: prefix + 16 hex digits from the OS's random source.
  static std::string new_id(const char* prefix);
  // True for the shape new_id produces (guards paths and keys against "../" and friends).
  static bool valid_id(const std::string& id);
};

std::span<const uint8_t> as_bytes(const std::string& text);

// The ids a replica must look at to match the store, from one listing: `listed`, acknowledged
// now (sorted; the listing says so, no need to ask about each again, which on S3 is a request
// per id), and `unlisted`, the ones `loaded` (a map keyed by id) holds that the store no
// longer lists (deleted elsewhere).
struct IdsToSync {
  std::vector<std::string> listed, unlisted;
};
template <typename LoadedMap>
Result<IdsToSync> ids_to_sync(const Storage& store, ResourceKind kind, const LoadedMap& loaded) {
  IdsToSync out;
  SOLIDTEX_ASSIGN_OR_RETURN(out.listed, store.ids(kind));
  for (const auto& entry : loaded)
    if (!std::binary_search(out.listed.begin(), out.listed.end(), entry.first)) out.unlisted.push_back(entry.first);
  return out;
}

// Where `solidtex serve` keeps its data: --data DIR (local) or --storage s3://bucket/prefix
// with --s3-endpoint URL; credentials for S3 come from the environment (s3_storage.h).
struct StorageConfig {
  std::string data_dir;     // the local directory, used when `storage` is empty
  std::string storage;      // "" or s3://bucket[/prefix]
  std::string s3_endpoint;  // http(s)://host[:port] of the S3-compatible server (path-style)
};

// Opens the configured backend: checks that it can be reached and listed with the given
// credentials (an error naming what is wrong otherwise) and removes old leftovers, reporting
// what it did into `report`.
Result<std::unique_ptr<Storage>> open_storage(const StorageConfig& config, std::vector<std::string>* report);

}  // namespace solidtex::server
