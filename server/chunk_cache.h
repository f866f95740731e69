// Encoded chunks of the array views (chunked_arrays.h), kept so that a chunk asked for again
// costs a map lookup instead of a synthesis request through the voxel cache, sRGB quantisation
// and zstd: array viewers re-read the same chunks all the time. Keyed by the chunk's strong ETag,
// which names the volume's spec, format, dataset and chunk, so an entry can never be stale.
// Bounded: `budget_bytes` counts the bodies plus a fixed overhead per entry; least recently used
// entries go first. Thread-safe (one mutex).
#pragma once

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <utility>

namespace solidtex::server {

class ChunkCache {
 public:
  explicit ChunkCache(int64_t budget_bytes) : budget_(budget_bytes) {}
  std::shared_ptr<const std::string> find(const std::string& etag);
  void insert(const std::string& etag, std::shared_ptr<const std::string> body);
  int64_t bytes() const;
  int64_t entries() const;
  static constexpr int64_t kEntryOverhead = 256;  // key, node, map bucket, shared_ptr control block

 private:
  using Entry = std::pair<std::string, std::shared_ptr<const std::string>>;
  mutable std::mutex mutex_;
  int64_t budget_;
  int64_t bytes_ = 0;
  std::list<Entry> lru_;  // most recently used first
  std::unordered_map<std::string, std::list<Entry>::iterator> index_;
};

}  // namespace solidtex::server
