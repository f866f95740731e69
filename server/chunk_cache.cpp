#include "chunk_cache.h"

namespace solidtex::server {

std::shared_ptr<const std::string> ChunkCache::find(const std::string& etag) {
  std::lock_guard<std::mutex> g(mutex_);
  auto it = index_.find(etag);
  if (it == index_.end()) return nullptr;
  lru_.splice(lru_.begin(), lru_, it->second);
  return it->second->second;
}

void ChunkCache::insert(const std::string& etag, std::shared_ptr<const std::string> body) {
  const int64_t cost = int64_t(body->size() + etag.size()) + kEntryOverhead;
  std::lock_guard<std::mutex> g(mutex_);
  if (cost > budget_ || index_.count(etag)) return;
  lru_.emplace_front(etag, std::move(body));
  index_[etag] = lru_.begin();
  bytes_ += cost;
  while (bytes_ > budget_) {
    const Entry& last = lru_.back();
    bytes_ -= int64_t(last.second->size() + last.first.size()) + kEntryOverhead;
    index_.erase(last.first);
    lru_.pop_back();
  }
}

int64_t ChunkCache::bytes() const {
  std::lock_guard<std::mutex> g(mutex_);
  return bytes_;
}

int64_t ChunkCache::entries() const {
  std::lock_guard<std::mutex> g(mutex_);
  return int64_t(index_.size());
}

}  // namespace solidtex::server
