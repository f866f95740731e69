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
// directories without their acknowledging file. Deleting renames the directory to ".trash-<id>"
// (atomic) before removing it. Thread-safe as the file system is; callers serialise writes to
// the same file.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/status.h"

namespace solidtex::server {

enum class ResourceKind { kExemplar, kField, kVolume, kMesh };

class DataStore {
 public:
  static Result<std::unique_ptr<DataStore>> open(const std::string& root, std::vector<std::string>* report);

  const std::string& root() const { return root_; }
  std::string path(ResourceKind kind, const std::string& id, const std::string& file = {}) const;
  Status create(ResourceKind kind, const std::string& id);
  Status write(ResourceKind kind, const std::string& id, const std::string& file, std::span<const uint8_t> bytes);
  Status write_text(ResourceKind kind, const std::string& id, const std::string& file, const std::string& text);
  Result<std::vector<uint8_t>> read(ResourceKind kind, const std::string& id, const std::string& file,
                                    int64_t max_bytes = int64_t(1) << 32) const;
  Result<std::string> read_text(ResourceKind kind, const std::string& id, const std::string& file) const;
  bool exists(ResourceKind kind, const std::string& id, const std::string& file) const;
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

// The file whose presence acknowledges a resource of that kind.
const char* acknowledging_file(ResourceKind kind);

}  // namespace solidtex::server
