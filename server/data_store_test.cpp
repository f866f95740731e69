#include "data_store.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace solidtex::server {
namespace {

fs::path fresh_dir(const char* name) {
  fs::path p = fs::temp_directory_path() / (std::string("solidtex_store_") + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

void touch(const fs::path& p, const std::string& text = "x") {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

TEST(DataStore, RoundTripsFilesAndListsOnlyAcknowledgedResources) {
  const fs::path root = fresh_dir("roundtrip");
  auto store = DataStore::open(root.string(), nullptr);
  ASSERT_TRUE(store.is_ok()) << store.status().to_string();
  const std::string id = DataStore::new_id("ex_");
  ASSERT_TRUE(DataStore::valid_id(id));
  ASSERT_TRUE((*store)->create(ResourceKind::kExemplar, id).is_ok());
  ASSERT_TRUE((*store)->write_text(ResourceKind::kExemplar, id, "xy.img", "pixels").is_ok());
  EXPECT_TRUE((*store)->ids(ResourceKind::kExemplar).empty());  // not acknowledged yet
  ASSERT_TRUE((*store)->write_text(ResourceKind::kExemplar, id, "meta.json", "{}").is_ok());
  EXPECT_EQ((*store)->ids(ResourceKind::kExemplar), std::vector<std::string>{id});
  auto text = (*store)->read_text(ResourceKind::kExemplar, id, "xy.img");
  ASSERT_TRUE(text.is_ok());
  EXPECT_EQ(*text, "pixels");
  ASSERT_TRUE((*store)->remove(ResourceKind::kExemplar, id).is_ok());
  EXPECT_TRUE((*store)->ids(ResourceKind::kExemplar).empty());
  EXPECT_FALSE(fs::exists((*store)->path(ResourceKind::kExemplar, id)));
  fs::remove_all(root);
}

TEST(DataStore, OpenRemovesAndReportsHalfWrittenLeftoversButKeepsAcknowledgedResources) {
  const fs::path root = fresh_dir("leftovers");
  touch(root / "volumes" / "vol_0123456789abcdef" / "volume.json", "{}");         // complete
  touch(root / "volumes" / "vol_0123456789abcdef" / ".volume.json.tmp-42");       // stray temporary
  touch(root / "exemplars" / "ex_00000000000000aa" / "xy.img");                   // never acknowledged
  touch(root / "fields" / ".trash-fld_00000000000000bb" / "r1.json");             // interrupted delete
  touch(root / "fields" / ".r1.json.tmp-7");                                      // stray temporary
  std::vector<std::string> report;
  auto store = DataStore::open(root.string(), &report);
  ASSERT_TRUE(store.is_ok());
  EXPECT_EQ(report.size(), 4u);
  EXPECT_EQ((*store)->ids(ResourceKind::kVolume), std::vector<std::string>{"vol_0123456789abcdef"});
  EXPECT_TRUE(fs::exists(root / "volumes" / "vol_0123456789abcdef" / "volume.json"));
  EXPECT_FALSE(fs::exists(root / "volumes" / "vol_0123456789abcdef" / ".volume.json.tmp-42"));
  EXPECT_FALSE(fs::exists(root / "exemplars" / "ex_00000000000000aa"));
  EXPECT_FALSE(fs::exists(root / "fields" / ".trash-fld_00000000000000bb"));
  fs::remove_all(root);
}

TEST(DataStore, RejectsIdsThatCouldEscapeTheDirectory) {
  EXPECT_FALSE(DataStore::valid_id("../etc"));
  EXPECT_FALSE(DataStore::valid_id("ex_A/B"));
  EXPECT_FALSE(DataStore::valid_id(""));
  EXPECT_TRUE(DataStore::valid_id("vol_0123456789abcdef"));
}

}  // namespace
}  // namespace solidtex::server
