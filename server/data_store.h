// Persistence of everything the service acknowledges, under one data directory:
//   exemplars/<id>/<part>.img   uploaded image bytes (xy, yz, zx, mask, mask_yz, mask_zx)
//   exemplars/<id>/meta.json    written after the images: its presence acknowledges the upload
//   exemplars/<id>/table.stx    the analysis output, then result.json (reports or the error)
//   fields/<id>/r<N>.stf, r<N>.json   revision N of a field (the .json last)
//   volumes/<id>/field.stf      the volume's own copy of its field (optional), then volume.json
//   meshes/<id>/source.mesh     the uploaded bytes, then meta.json
// Every file is written atomically (temporary file, fsync, rename, fsync of the directory:
// byte_io.h), and a resource's acknowledging file is written last, so a kill -9 at any moment
// leaves either the whole resource or a leftover. open() removes leftovers and reports them:
// temporaries (".*.tmp-*"), ".trash-*" directories (interrupted deletes) and resource
// directories without their acknowledging file. Several replicas may share one directory
// (README, "Several replicas on one data directory"): a leftover may then be another live
// replica's write in progress, so open() removes only leftovers whose newest modification is
// older than kLeftoverGraceSeconds and reports the younger ones as skipped. Deleting renames
// the directory to ".trash-<id>" (atomic) before removing it. Thread-safe as the file system
// is; callers serialise writes to the same file.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/status.h"

namespace solidtex::server {

enum class ResourceKind { kExemplar, kField, kVolume, kMesh };

// Age (newest mtime of the entry and, for a directory, of its files) below which open() leaves
// a leftover alone: another replica may be writing it right now. Uploads and deletes finish
// well within it.
constexpr double kLeftoverGraceSeconds = 600;

class DataStore {
 public:
  static Result<std::unique_ptr<DataStore>> open(const std::string& root, std::vector<std::string>* report,
                                                 double grace_seconds = kLeftoverGraceSeconds);

  const std::string& root() const { return root_; }
  std::string path(ResourceKind kind, const std::string& id, const std::string& file = {}) const;
  Status create(ResourceKind kind, const std::string& id);
  Status write(ResourceKind kind, const std::string& id, const std::string& file, std::span<const uint8_t> bytes);
  Status write_text(ResourceKind kind, const std::string& id, const std::string& file, const std::string& text);
  Result<std::vector<uint8_t>> read(ResourceKind kind, const std::string& id, const std::string& file,
                                    int64_t max_bytes = int64_t(1) << 32) const;
  Result<std::string> read_text(ResourceKind kind, const std::string& id, const std::string& file) const;
  bool exists(ResourceKind kind, const std::string& id, const std::string& file) const;
  // The resource is acknowledged (its acknowledging file is present): written completely,
  // possibly by another replica, and not deleted.
  bool acknowledged(ResourceKind kind, const std::string& id) const;
  // Files of one resource directory, sorted.
  std::vector<std::string> files(ResourceKind kind, const std::string& id) const;
  // Ids of the resources of a kind that are acknowledged, sorted.
  std::vector<std::string> ids(ResourceKind kind) const;
  Status remove(ResourceKind kind, const std::string& id);

  // A fresh opaque id: prefix + 16 hex digits from the OS's random source.
  static std::string new_id(const char* prefix);
  // True for the shape new_id produces (guards paths against "../" and friends).
  static bool valid_id(const std::string& id);

 private:
  explicit DataStore(std::string root) : root_(std::move(root)) {}
  std::string root_;
};

// The ids a replica must look at to match the store: those stored now (sorted) followed by the
// ones `loaded` (a map keyed by id) holds that the store no longer has (deleted elsewhere).
template <typename LoadedMap>
std::vector<std::string> stored_and_loaded_ids(const DataStore& store, ResourceKind kind, const LoadedMap& loaded) {
  std::vector<std::string> ids = store.ids(kind);
  const size_t stored = ids.size();
  for (const auto& entry : loaded)
    if (!std::binary_search(ids.begin(), ids.begin() + std::ptrdiff_t(stored), entry.first)) ids.push_back(entry.first);
  return ids;
}

// The file whose presence acknowledges a resource of that kind.
const char* acknowledging_file(ResourceKind kind);

}  // namespace solidtex::server
