// ETags of the chunked-array views; the live service is tested by tests/python/test_arrays.py
// (every metadata document its own ETag, the same on two GETs and after a restart).
#include "array_etag.h"

#include <gtest/gtest.h>

#include <set>

namespace solidtex::server {
namespace {

TEST(ArrayEtag, HashIsFnv1a64OnEveryBuild) {
  // the published FNV-1a 64 test vectors: a tag computed today is the tag after a restart
  EXPECT_EQ(fnv1a_hex(""), "cbf29ce484222325");
  EXPECT_EQ(fnv1a_hex("a"), "af63dc4c8601ec8c");
  EXPECT_EQ(fnv1a_hex("foobar"), "85944171f73967e8");
}

TEST(ArrayEtag, EveryMetadataDocumentHasItsOwnTag) {
  const std::string base = "/v1/volumes/vol_a/";
  std::set<std::string> seen;
  for (const char* doc : {"zarr/zarr.json", "zarr/0/zarr.json", "zarr/1/zarr.json", "zarr2/.zgroup", "zarr2/.zattrs",
                          "zarr2/0/.zarray", "zarr2/1/.zarray", "precomputed/info", "precomputed-jpeg/info"}) {
    const std::string etag = metadata_etag("0123456789abcdef", 1024, base + doc);
    EXPECT_EQ(etag, metadata_etag("0123456789abcdef", 1024, base + doc)) << doc;
    EXPECT_TRUE(seen.insert(etag).second) << doc << " shares " << etag;
  }
  // the same document of another volume (same spec, so same content tag: the id is in the path)
  EXPECT_TRUE(seen.insert(metadata_etag("0123456789abcdef", 1024, "/v1/volumes/vol_b/zarr/zarr.json")).second);
  // another spec or another window
  EXPECT_TRUE(seen.insert(metadata_etag("fedcba9876543210", 1024, base + "zarr/zarr.json")).second);
  EXPECT_TRUE(seen.insert(metadata_etag("0123456789abcdef", 512, base + "zarr/zarr.json")).second);
}

TEST(ArrayEtag, TagsAreStrongAndQuotedWhateverThePathHolds) {
  for (const std::string& path : {std::string("/v1/volumes/a b\"c/zarr/zarr.json"), std::string("/x\x01\xff", 4)}) {
    const std::string etag = metadata_etag("0123456789abcdef", 64, path);
    ASSERT_GE(etag.size(), 2u);
    EXPECT_EQ(etag.front(), '"');
    EXPECT_EQ(etag.back(), '"');
    for (size_t i = 1; i + 1 < etag.size(); ++i) {  // etagc = %x21 / %x23-7E
      const unsigned char c = static_cast<unsigned char>(etag[i]);
      EXPECT_TRUE(c == 0x21 || (c >= 0x23 && c <= 0x7e)) << etag;
    }
  }
  EXPECT_EQ(chunk_etag("0123456789abcdef", "zarr3", 1, "0.1.2"), "\"0123456789abcdef-zarr3-1-0.1.2\"");
  EXPECT_NE(chunk_etag("0123456789abcdef", "zarr3", 1, "0.1.2"), chunk_etag("0123456789abcdef", "zarr2", 1, "0.1.2"));
}

}  // namespace
}  // namespace solidtex::server
