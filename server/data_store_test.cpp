#include "data_store.h"

#include <gtest/gtest.h>

#include <chrono>
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

// Sets the modification time of `p` (and of everything below it) `seconds` into the past.
void age(const fs::path& p, double seconds) {
  const auto t = fs::file_time_type::clock::now() -
                 std::chrono::duration_cast<fs::file_time_type::duration>(std::chrono::duration<double>(seconds));
  if (fs::is_directory(p))
    for (const auto& e : fs::recursive_directory_iterator(p)) fs::last_write_time(e.path(), t);
  fs::last_write_time(p, t);
}

TEST(DataStore, RoundTripsFilesAndListsOnlyAcknowledgedResources) {
  const fs::path root = fresh_dir("roundtrip");
  auto store = DataStore::open(root.string(), nullptr);
  ASSERT_TRUE(store.is_ok()) << store.status().to_string();
  const std::string id = DataStore::new_id("ex_");
  ASSERT_TRUE(DataStore::valid_id(id));
  ASSERT_TRUE((*store)->create(ResourceKind::kExemplar, id).is_ok());
  ASSERT_TRUE((*store)->write_text(ResourceKind::kExemplar, id, "xy.img", "pixels").is_ok());
  EXPECT_TRUE((*store)->ids(ResourceKind::kExemplar).value().empty());  // not acknowledged yet
  ASSERT_TRUE((*store)->write_text(ResourceKind::kExemplar, id, "meta.json", "{}").is_ok());
  EXPECT_EQ((*store)->ids(ResourceKind::kExemplar).value(), std::vector<std::string>{id});
  auto text = (*store)->read_text(ResourceKind::kExemplar, id, "xy.img");
  ASSERT_TRUE(text.is_ok());
  EXPECT_EQ(*text, "pixels");
  ASSERT_TRUE((*store)->remove(ResourceKind::kExemplar, id).is_ok());
  EXPECT_TRUE((*store)->ids(ResourceKind::kExemplar).value().empty());
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
  for (const char* p : {"volumes/vol_0123456789abcdef/.volume.json.tmp-42", "exemplars/ex_00000000000000aa",
                        "fields/.trash-fld_00000000000000bb", "fields/.r1.json.tmp-7"})
    age(root / p, kLeftoverGraceSeconds + 60);  // older than the grace period
  std::vector<std::string> report;
  auto store = DataStore::open(root.string(), &report);
  ASSERT_TRUE(store.is_ok());
  EXPECT_EQ(report.size(), 4u);
  EXPECT_EQ((*store)->ids(ResourceKind::kVolume).value(), std::vector<std::string>{"vol_0123456789abcdef"});
  EXPECT_TRUE(fs::exists(root / "volumes" / "vol_0123456789abcdef" / "volume.json"));
  EXPECT_FALSE(fs::exists(root / "volumes" / "vol_0123456789abcdef" / ".volume.json.tmp-42"));
  EXPECT_FALSE(fs::exists(root / "exemplars" / "ex_00000000000000aa"));
  EXPECT_FALSE(fs::exists(root / "fields" / ".trash-fld_00000000000000bb"));
  fs::remove_all(root);
}

// Several replicas share one directory: a leftover younger than the grace period may be another
// live replica's write in progress, so it is kept and reported as skipped; older ones go.
TEST(DataStore, OpenKeepsLeftoversYoungerThanTheGracePeriodAndReportsThemSkipped) {
  const fs::path root = fresh_dir("grace");
  touch(root / "exemplars" / "ex_00000000000000aa" / "xy.img");            // being uploaded elsewhere
  touch(root / "exemplars" / "ex_00000000000000bb" / "xy.img");            // abandoned long ago
  age(root / "exemplars" / "ex_00000000000000bb", kLeftoverGraceSeconds + 60);
  touch(root / "volumes" / "vol_0123456789abcdef" / "volume.json", "{}");
  touch(root / "volumes" / "vol_0123456789abcdef" / ".volume.json.tmp-42");  // being written elsewhere
  touch(root / "meshes" / ".trash-mesh_00000000000000cc" / "meta.json");     // being deleted elsewhere
  // An old directory with a file written just now counts as young (its newest modification).
  touch(root / "fields" / "fld_00000000000000dd" / "r1.stf");
  age(root / "fields" / "fld_00000000000000dd", kLeftoverGraceSeconds + 60);
  touch(root / "fields" / "fld_00000000000000dd" / "r1.stf.part");
  std::vector<std::string> report;
  auto store = DataStore::open(root.string(), &report);
  ASSERT_TRUE(store.is_ok());
  EXPECT_TRUE(fs::exists(root / "exemplars" / "ex_00000000000000aa" / "xy.img"));
  EXPECT_FALSE(fs::exists(root / "exemplars" / "ex_00000000000000bb"));
  EXPECT_TRUE(fs::exists(root / "volumes" / "vol_0123456789abcdef" / ".volume.json.tmp-42"));
  EXPECT_TRUE(fs::exists(root / "meshes" / ".trash-mesh_00000000000000cc"));
  EXPECT_TRUE(fs::exists(root / "fields" / "fld_00000000000000dd"));
  int skipped = 0, removed = 0;
  for (const std::string& line : report) {
    skipped += line.rfind("skipped young leftover", 0) == 0;
    removed += line.rfind("removed half-written leftover", 0) == 0;
  }
  EXPECT_EQ(skipped, 4) << ::testing::PrintToString(report);
  EXPECT_EQ(removed, 1) << ::testing::PrintToString(report);
  EXPECT_TRUE((*store)->ids(ResourceKind::kExemplar).value().empty());  // unacknowledged: never listed
  // A grace period of 0 (a single replica that knows it is alone) removes them all.
  report.clear();
  ASSERT_TRUE(DataStore::open(root.string(), &report, 0).is_ok());
  EXPECT_EQ(report.size(), 4u) << ::testing::PrintToString(report);
  EXPECT_FALSE(fs::exists(root / "exemplars" / "ex_00000000000000aa"));
  EXPECT_FALSE(fs::exists(root / "meshes" / ".trash-mesh_00000000000000cc"));
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
