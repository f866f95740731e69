#include "chunk_cache.h"

#include <gtest/gtest.h>

namespace solidtex::server {
namespace {

std::shared_ptr<const std::string> body(size_t n, char c) { return std::make_shared<const std::string>(n, c); }

TEST(ChunkCache, KeepsWithinItsBudgetDroppingTheLeastRecentlyUsed) {
  const int64_t entry = 1000 + 2 + ChunkCache::kEntryOverhead;  // body + key "k?" + overhead
  ChunkCache c(3 * entry);
  c.insert("k1", body(1000, '1'));
  c.insert("k2", body(1000, '2'));
  c.insert("k3", body(1000, '3'));
  EXPECT_EQ(c.entries(), 3);
  EXPECT_EQ(c.bytes(), 3 * entry);
  ASSERT_NE(c.find("k1"), nullptr);  // k2 is now the least recently used
  c.insert("k4", body(1000, '4'));
  EXPECT_EQ(c.entries(), 3);
  EXPECT_LE(c.bytes(), 3 * entry);
  EXPECT_EQ(c.find("k2"), nullptr);
  EXPECT_EQ(*c.find("k1"), std::string(1000, '1'));
  EXPECT_EQ(*c.find("k4"), std::string(1000, '4'));
  c.insert("k4", body(10, 'x'));  // an ETag names its bytes: the first stays
  EXPECT_EQ(c.find("k4")->size(), 1000u);
  c.insert("big", body(size_t(4 * entry), 'b'));  // larger than the budget: not kept
  EXPECT_EQ(c.find("big"), nullptr);
  ChunkCache off(0);
  off.insert("k", body(1, 'a'));
  EXPECT_EQ(off.find("k"), nullptr);
  EXPECT_EQ(off.bytes(), 0);
}

}  // namespace
}  // namespace solidtex::server
