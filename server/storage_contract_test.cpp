// The Storage contract (storage.h), checked on every backend: the local directory always, and
// an S3-compatible server when SOLIDTEX_TEST_S3_STORAGE (s3://bucket/prefix) and
// SOLIDTEX_TEST_S3_ENDPOINT are set with AWS_ACCESS_KEY_ID / AWS_SECRET_ACCESS_KEY
// (tests/python/test_s3_storage.py runs these against versitygw; skipped otherwise).
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "data_store.h"
#include "s3_storage.h"

namespace fs = std::filesystem;

namespace solidtex::server {
namespace {

class StorageContract : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    if (GetParam() == "local") {
      root_ = fs::temp_directory_path() / ("solidtex_contract_" + std::to_string(::getpid()) + "_" +
                                           ::testing::UnitTest::GetInstance()->current_test_info()->name());
      fs::remove_all(root_);
      auto s = DataStore::open(root_.string(), nullptr);
      ASSERT_TRUE(s.is_ok()) << s.status().to_string();
      store_ = std::move(*s);
      return;
    }
    const char* url = std::getenv("SOLIDTEX_TEST_S3_STORAGE");
    const char* endpoint = std::getenv("SOLIDTEX_TEST_S3_ENDPOINT");
    if (!url || !endpoint) GTEST_SKIP() << "SOLIDTEX_TEST_S3_STORAGE / SOLIDTEX_TEST_S3_ENDPOINT not set";
    // A prefix of its own per test, so that runs never see each other's objects.
    auto params = S3Params::from_environment(std::string(url) + "/" + Storage::new_id("t_"), endpoint);
    ASSERT_TRUE(params.is_ok()) << params.status().to_string();
    auto s = S3Storage::open(*params, nullptr);
    ASSERT_TRUE(s.is_ok()) << s.status().to_string();
    store_ = std::move(*s);
  }
  void TearDown() override {
    if (!root_.empty()) fs::remove_all(root_);
  }
  Storage& store() { return *store_; }

  fs::path root_;
  std::unique_ptr<Storage> store_;
};

std::string text(const std::vector<uint8_t>& b) { return {b.begin(), b.end()}; }

TEST_P(StorageContract, WritesReadsListsAndRemoves) {
  Storage& s = store();
  const std::string id = Storage::new_id("ex_");
  ASSERT_TRUE(s.create(ResourceKind::kExemplar, id).is_ok());
  ASSERT_TRUE(s.write_text(ResourceKind::kExemplar, id, "xy.img", "pixels").is_ok());
  EXPECT_TRUE(s.ids(ResourceKind::kExemplar).value().empty());  // not acknowledged yet
  EXPECT_FALSE(s.acknowledged(ResourceKind::kExemplar, id).value());
  ASSERT_TRUE(s.write_text(ResourceKind::kExemplar, id, "meta.json", "{}").is_ok());
  EXPECT_TRUE(s.acknowledged(ResourceKind::kExemplar, id).value());
  EXPECT_EQ(s.ids(ResourceKind::kExemplar).value(), std::vector<std::string>{id});
  EXPECT_TRUE(s.ids(ResourceKind::kMesh).value().empty());
  EXPECT_EQ(s.files(ResourceKind::kExemplar, id).value(), (std::vector<std::string>{"meta.json", "xy.img"}));
  EXPECT_EQ(s.read_text(ResourceKind::kExemplar, id, "xy.img").value(), "pixels");
  ASSERT_TRUE(s.write_text(ResourceKind::kExemplar, id, "xy.img", "replaced").is_ok());
  EXPECT_EQ(s.read_text(ResourceKind::kExemplar, id, "xy.img").value(), "replaced");
  EXPECT_TRUE(s.exists(ResourceKind::kExemplar, id, "xy.img").value());
  EXPECT_FALSE(s.exists(ResourceKind::kExemplar, id, "yz.img").value());
  EXPECT_EQ(s.read(ResourceKind::kExemplar, id, "yz.img").status().code(), StatusCode::kNotFound);
  EXPECT_EQ(s.read(ResourceKind::kExemplar, id, "xy.img", 3).status().code(), StatusCode::kTooLarge);
  // An empty object is an object.
  ASSERT_TRUE(s.write_text(ResourceKind::kExemplar, id, "empty", "").is_ok());
  EXPECT_TRUE(s.read(ResourceKind::kExemplar, id, "empty").value().empty());
  ASSERT_TRUE(s.remove(ResourceKind::kExemplar, id).is_ok());
  EXPECT_TRUE(s.ids(ResourceKind::kExemplar).value().empty());
  EXPECT_FALSE(s.acknowledged(ResourceKind::kExemplar, id).value());
  EXPECT_TRUE(s.files(ResourceKind::kExemplar, id).value().empty());
}

TEST_P(StorageContract, MalformedIdsNeverReachTheStore) {
  Storage& s = store();
  for (const std::string bad : {"../etc", "ex_A/B", "", "ex_../../x"}) {
    EXPECT_FALSE(s.create(ResourceKind::kVolume, bad).is_ok()) << bad;
    EXPECT_FALSE(s.write_text(ResourceKind::kVolume, bad, "volume.json", "{}").is_ok()) << bad;
    EXPECT_FALSE(s.create_new_text(ResourceKind::kVolume, bad, "volume.json", "{}").is_ok()) << bad;
    EXPECT_EQ(s.read(ResourceKind::kVolume, bad, "volume.json").status().code(), StatusCode::kNotFound) << bad;
    EXPECT_FALSE(s.exists(ResourceKind::kVolume, bad, "volume.json").value()) << bad;
  }
}

TEST_P(StorageContract, CreateNewIsWriteOnce) {
  Storage& s = store();
  const std::string id = Storage::new_id("fld_");
  ASSERT_TRUE(s.create(ResourceKind::kField, id).is_ok());
  auto first = s.create_new_text(ResourceKind::kField, id, "r1.json", "first");
  ASSERT_TRUE(first.is_ok()) << first.status().to_string();
  EXPECT_FALSE(first->empty());
  auto second = s.create_new_text(ResourceKind::kField, id, "r1.json", "second");
  ASSERT_FALSE(second.is_ok());
  EXPECT_EQ(second.status().code(), StatusCode::kAlreadyExists);
  EXPECT_EQ(s.read_text(ResourceKind::kField, id, "r1.json").value(), "first");
  EXPECT_EQ(s.read_versioned(ResourceKind::kField, id, "r1.json").value().etag, *first);
}

// Two replicas must never both write revision N of a field: of many concurrent creators of one
// object exactly one wins, and the stored content is the winner's.
TEST_P(StorageContract, OfConcurrentCreatorsExactlyOneWins) {
  Storage& s = store();
  const std::string id = Storage::new_id("fld_");
  ASSERT_TRUE(s.create(ResourceKind::kField, id).is_ok());
  for (int round = 0; round < 3; ++round) {
    const std::string file = std::to_string(round + 2) + ".stf";  // "r" + ...: GCC 12 warns falsely (-Wrestrict)
    std::atomic<int> wins{0}, lost{0};
    std::atomic<int> winner{-1};
    std::vector<std::thread> racers;
    for (int i = 0; i < 8; ++i)
      racers.emplace_back([&, i] {
        auto r = s.create_new_text(ResourceKind::kField, id, file, "writer " + std::to_string(i));
        if (r.is_ok()) {
          ++wins;
          winner = i;
        } else if (r.status().code() == StatusCode::kAlreadyExists) {
          ++lost;
        } else {
          ADD_FAILURE() << r.status().to_string();
        }
      });
    for (auto& t : racers) t.join();
    EXPECT_EQ(wins.load(), 1) << file;
    EXPECT_EQ(lost.load(), 7) << file;
    EXPECT_EQ(s.read_text(ResourceKind::kField, id, file).value(), "writer " + std::to_string(winner.load()));
  }
}

TEST_P(StorageContract, LeasesAreReplacedAndRemovedOnlyIfUnchanged) {
  Storage& s = store();
  const std::string id = Storage::new_id("ex_");
  ASSERT_TRUE(s.create(ResourceKind::kExemplar, id).is_ok());
  auto created = s.create_new_text(ResourceKind::kExemplar, id, "lease", "{\"owner\": \"a\", \"n\": 1}");
  ASSERT_TRUE(created.is_ok()) << created.status().to_string();
  auto read = s.read_versioned(ResourceKind::kExemplar, id, "lease");
  ASSERT_TRUE(read.is_ok());
  EXPECT_EQ(text(read->bytes), "{\"owner\": \"a\", \"n\": 1}");
  EXPECT_EQ(read->etag, *created);
  EXPECT_GE(read->age_seconds, 0);
  EXPECT_LT(read->age_seconds, 60);

  // Renewal with the current etag goes through and yields a new etag.
  auto renewed = s.replace_if_match(ResourceKind::kExemplar, id, "lease", as_bytes("{\"owner\": \"a\", \"n\": 2}"), *created);
  ASSERT_TRUE(renewed.is_ok()) << renewed.status().to_string();
  EXPECT_NE(*renewed, *created);
  // A takeover based on the stale etag fails and changes nothing.
  auto stale = s.replace_if_match(ResourceKind::kExemplar, id, "lease", as_bytes("{\"owner\": \"b\"}"), *created);
  ASSERT_FALSE(stale.is_ok());
  EXPECT_EQ(stale.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(s.read_text(ResourceKind::kExemplar, id, "lease").value(), "{\"owner\": \"a\", \"n\": 2}");
  // So does a release with it.
  EXPECT_EQ(s.remove_if_match(ResourceKind::kExemplar, id, "lease", *created).code(), StatusCode::kFailedPrecondition);
  EXPECT_TRUE(s.exists(ResourceKind::kExemplar, id, "lease").value());
  // The current etag releases it; then it is gone for conditional operations too.
  EXPECT_TRUE(s.remove_if_match(ResourceKind::kExemplar, id, "lease", *renewed).is_ok());
  EXPECT_FALSE(s.exists(ResourceKind::kExemplar, id, "lease").value());
  EXPECT_EQ(s.read_versioned(ResourceKind::kExemplar, id, "lease").status().code(), StatusCode::kNotFound);
  const Status again = s.remove_if_match(ResourceKind::kExemplar, id, "lease", *renewed);
  EXPECT_TRUE(again.is_ok() || again.code() == StatusCode::kNotFound) << again.to_string();
  EXPECT_EQ(s.replace_if_match(ResourceKind::kExemplar, id, "lease", as_bytes("x"), *renewed).status().code(),
            StatusCode::kFailedPrecondition);
  // And it can be claimed afresh.
  EXPECT_TRUE(s.create_new_text(ResourceKind::kExemplar, id, "lease", "{\"owner\": \"c\"}").is_ok());
}

// Several replicas taking over one expired lease at once: exactly one succeeds.
TEST_P(StorageContract, OfConcurrentTakeoversExactlyOneWins) {
  Storage& s = store();
  const std::string id = Storage::new_id("ex_");
  ASSERT_TRUE(s.create(ResourceKind::kExemplar, id).is_ok());
  for (int round = 0; round < 3; ++round) {
    const std::string old_owner = "{\"owner\": \"dead " + std::to_string(round) + "\"}";
    if (round == 0) ASSERT_TRUE(s.create_new_text(ResourceKind::kExemplar, id, "lease", old_owner).is_ok());
    else ASSERT_TRUE(s.write_text(ResourceKind::kExemplar, id, "lease", old_owner).is_ok());
    const std::string etag = s.read_versioned(ResourceKind::kExemplar, id, "lease").value().etag;
    std::atomic<int> wins{0}, winner{-1};
    std::vector<std::thread> racers;
    for (int i = 0; i < 8; ++i)
      racers.emplace_back([&, i] {
        const std::string mine = "{\"owner\": \"r" + std::to_string(i) + "\"}";
        auto r = s.replace_if_match(ResourceKind::kExemplar, id, "lease", as_bytes(mine), etag);
        if (r.is_ok()) {
          ++wins;
          winner = i;
        } else {
          EXPECT_EQ(r.status().code(), StatusCode::kFailedPrecondition) << r.status().to_string();
        }
      });
    for (auto& t : racers) t.join();
    EXPECT_EQ(wins.load(), 1);
    EXPECT_EQ(s.read_text(ResourceKind::kExemplar, id, "lease").value(),
              "{\"owner\": \"r" + std::to_string(winner.load()) + "\"}");
  }
}

TEST_P(StorageContract, LargeObjectsRoundTrip) {
  Storage& s = store();
  const std::string id = Storage::new_id("ex_");
  ASSERT_TRUE(s.create(ResourceKind::kExemplar, id).is_ok());
  std::vector<uint8_t> big(size_t(5) << 20);  // over curl's 1 MiB Expect: 100-continue threshold
  for (size_t i = 0; i < big.size(); ++i) big[i] = uint8_t((i * 2654435761u) >> 13);
  ASSERT_TRUE(s.write(ResourceKind::kExemplar, id, "table.stx", big).is_ok());
  EXPECT_EQ(s.read(ResourceKind::kExemplar, id, "table.stx").value(), big);
  EXPECT_EQ(s.read(ResourceKind::kExemplar, id, "table.stx", int64_t(big.size()) - 1).status().code(),
            StatusCode::kTooLarge);
}

INSTANTIATE_TEST_SUITE_P(Backends, StorageContract, ::testing::Values("local", "s3"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace solidtex::server
