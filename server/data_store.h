// The local-directory Storage backend (storage.h), the default: everything the service
// acknowledges, under one data directory:
//   exemplars/<id>/<part>.img   uploaded image bytes (xy, yz, zx, mask, mask_yz, mask_zx)
//   exemplars/<id>/meta.json    written after the images: its presence acknowledges the upload
//   exemplars/<id>/table.stx    the analysis output, then result.json (reports or the error);
//                               lease and attempts: the analysis job's (exemplar_service.h)
//   fields/<id>/r<N>.stf, r<N>.json   revision N of a field (the .json last; both write-once)
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
// the directory to ".trash-<id>" (atomic) before removing it.
// Conditional operations (storage.h): create_new() writes a complete temporary file and
// link()s it to the name, which fails atomically when the name exists (also on NFS);
// replace_if_match() and remove_if_match() hold an exclusive flock() on the current file
// (the Linux NFS client maps it to a byte-range lock the server arbitrates) and check that
// the name still refers to the locked file, so concurrent ones serialise; the etag is a
// 64-bit FNV-1a hash of the content. Thread-safe; plain write()s of one file from two
// threads of one process must be serialised by the caller (they share a temporary name).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "storage.h"

namespace solidtex::server {

class DataStore : public Storage {
 public:
  static Result<std::unique_ptr<DataStore>> open(const std::string& root, std::vector<std::string>* report,
                                                 double grace_seconds = kLeftoverGraceSeconds);

  const std::string& root() const { return root_; }
  // The file's path: local only (tests and tools look at the bits on disk).
  std::string path(ResourceKind kind, const std::string& id, const std::string& file = {}) const;

  std::string describe() const override { return root_; }
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

  // The etag of `bytes` as this backend computes it (16 hex digits).
  static std::string etag_of(std::span<const uint8_t> bytes);

 private:
  explicit DataStore(std::string root) : root_(std::move(root)) {}
  std::string root_;
};

}  // namespace solidtex::server
