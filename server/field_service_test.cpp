#include "field_service.h"

#include "data_store.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

namespace fs = std::filesystem;

namespace solidtex::server {
namespace {

// A small sketch (a 6-cell shortest side: solves take milliseconds) and two more curves.
constexpr const char* kSketch =
    R"({"domain": {"min": [-8, -8, -8], "max": [40, 40, 24], "shortest_side_cells": 6},
        "curves": [{"points": [[0, 4, 8], [16, 12, 8], [30, 4, 8]], "plane_normal": [0, 0, 1], "axis": "x"}]})";
constexpr const char* kCurve2 = R"({"points": [[2, 30, 4], [30, 20, 4]], "plane_normal": [0, 0, 1], "axis": "x"})";
constexpr const char* kCurve3 = R"({"points": [[4, 2, 12], [4, 30, 12]], "plane_normal": [0, 0, 1], "axis": "y"})";

// Blocks every poll until released, so that the change polling it holds the field meanwhile.
class Gate : public Interrupter {
 public:
  bool was_interrupted(int) override {
    std::unique_lock<std::mutex> l(m_);
    entered_ = true;
    cv_.notify_all();
    cv_.wait(l, [&] { return open_; });
    return false;
  }
  void wait_entered() {
    std::unique_lock<std::mutex> l(m_);
    cv_.wait(l, [&] { return entered_; });
  }
  void release() {
    std::lock_guard<std::mutex> l(m_);
    open_ = true;
    cv_.notify_all();
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  bool entered_ = false, open_ = false;
};

// Asks to stop from its (n+1)-th poll on.
class StopAfter : public Interrupter {
 public:
  explicit StopAfter(int n) : n_(n) {}
  bool was_interrupted(int) override { return ++polls_ > n_; }
  int polls() const { return polls_.load(); }

 private:
  int n_;
  std::atomic<int> polls_{0};
};

struct Fixture {
  fs::path root = fs::temp_directory_path() / ("solidtex_fields_" + std::to_string(::getpid()));
  ServerConfig config;
  std::unique_ptr<DataStore> store;
  std::unique_ptr<FieldService> fields;
  Fixture() {
    fs::remove_all(root);
    store = std::move(DataStore::open(root.string(), nullptr)).value();
    fields = std::make_unique<FieldService>(*store, config);
    EXPECT_TRUE(fields->start(nullptr).is_ok());
  }
  ~Fixture() { fs::remove_all(root); }
  // A field at revision 2 (the sketch, then kCurve2).
  std::string field_at_revision_2() {
    auto created = fields->create(kSketch, null_interrupter());
    EXPECT_TRUE(created.is_ok()) << created.status().to_string();
    const std::string id = (*created)["id"];
    auto added = fields->add_curve(id, kCurve2, null_interrupter());
    EXPECT_TRUE(added.is_ok()) << added.status().to_string();
    return id;
  }
  int revision(const std::string& id) { return fields->get(id).value()["revision"].get<int>(); }
  bool has_file(const std::string& id, const std::string& name) { return store->exists(ResourceKind::kField, id, name).value(); }
};

TEST(FieldService, AStaleRevisionChangesNothingAndSaysTheCurrentOne) {
  Fixture f;
  const std::string id = f.field_at_revision_2();
  const auto bytes = f.fields->file_bytes(id).value();
  for (int stale : {1, 3}) {
    auto added = f.fields->add_curve(id, kCurve3, null_interrupter(), stale);
    ASSERT_FALSE(added.is_ok());
    EXPECT_EQ(added.status().code(), StatusCode::kFailedPrecondition);
    EXPECT_EQ(added.status().field(), "revision");
    EXPECT_NE(added.status().message().find("revision 2"), std::string::npos) << added.status().message();
    auto removed = f.fields->remove_last_curve(id, null_interrupter(), stale);
    ASSERT_FALSE(removed.is_ok());
    EXPECT_EQ(removed.status().code(), StatusCode::kFailedPrecondition);
    EXPECT_EQ(removed.status().field(), "revision");
  }
  EXPECT_EQ(f.revision(id), 2);
  EXPECT_FALSE(f.has_file(id, "r3.stf"));
  EXPECT_EQ(f.fields->file_bytes(id).value(), bytes);
  // The current revision goes through: an undo meant for revision 2, then an add meant for 3.
  auto undone = f.fields->remove_last_curve(id, null_interrupter(), 2);
  ASSERT_TRUE(undone.is_ok()) << undone.status().to_string();
  EXPECT_EQ((*undone)["revision"], 3);
  // A retry of that undo does not remove another curve.
  EXPECT_EQ(f.fields->remove_last_curve(id, null_interrupter(), 2).status().code(), StatusCode::kFailedPrecondition);
  auto added = f.fields->add_curve(id, kCurve3, null_interrupter(), 3);
  ASSERT_TRUE(added.is_ok()) << added.status().to_string();
  EXPECT_EQ((*added)["revision"], 4);
}

TEST(FieldService, TheRestoreScanPollsTheInterrupter) {
  Fixture f;
  const std::string id = f.field_at_revision_2();
  StopAfter stop(0);
  auto undone = f.fields->remove_last_curve(id, stop);
  ASSERT_FALSE(undone.is_ok());
  EXPECT_EQ(undone.status().code(), StatusCode::kCancelled);
  EXPECT_EQ(stop.polls(), 1);
  EXPECT_EQ(f.revision(id), 2);
  EXPECT_FALSE(f.has_file(id, "r3.stf"));
}

TEST(FieldService, AnEarlierRevisionThatCannotBeReadIsPassedOver) {
  Fixture f;
  const std::string id = f.field_at_revision_2();
  ASSERT_TRUE(f.fields->add_curve(id, kCurve3, null_interrupter()).is_ok());
  // Revision 2 is the one the undo would restore; without its .json it is skipped and the
  // two-curve sketch is solved afresh instead of the undo failing.
  fs::remove(f.store->path(ResourceKind::kField, id, "r2.json"));
  auto undone = f.fields->remove_last_curve(id, null_interrupter());
  ASSERT_TRUE(undone.is_ok()) << undone.status().to_string();
  EXPECT_EQ((*undone)["revision"], 4);
  EXPECT_EQ((*undone)["curves"], 2);
  // An undecodable .stf is passed over as well (here revision 1, the match of the next undo).
  std::ofstream(f.store->path(ResourceKind::kField, id, "r1.stf"), std::ios::binary) << "not a field";
  auto again = f.fields->remove_last_curve(id, null_interrupter());
  ASSERT_TRUE(again.is_ok()) << again.status().to_string();
  EXPECT_EQ((*again)["revision"], 5);
  EXPECT_EQ((*again)["curves"], 1);
}

TEST(FieldService, WaitingForABusyFieldStopsWhenTheInterrupterSays) {
  Fixture f;
  const std::string id = f.field_at_revision_2();
  Gate gate;
  Result<nlohmann::json> held = Status(StatusCode::kInternal, "not run");
  std::thread holder([&] { held = f.fields->remove_last_curve(id, gate); });
  gate.wait_entered();  // the undo holds the field, stopped in its restore scan
  for (int kind = 0; kind < 3; ++kind) {
    StopAfter stop(3);
    const auto t0 = std::chrono::steady_clock::now();
    const Status s = kind == 0   ? f.fields->add_curve(id, kCurve3, stop).status()
                     : kind == 1 ? f.fields->remove_last_curve(id, stop).status()
                                 : f.fields->remove(id, stop);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(s.code(), StatusCode::kCancelled) << kind << " " << s.to_string();
    EXPECT_EQ(stop.polls(), 4) << kind;   // one poll per 50 ms step
    EXPECT_LT(seconds, 2.0) << kind;
  }
  gate.release();
  holder.join();
  ASSERT_TRUE(held.is_ok()) << held.status().to_string();
  EXPECT_EQ((*held)["revision"], 3);
  EXPECT_EQ(f.revision(id), 3);
}

TEST(FieldService, DeletingWaitsForARunningChangeInsteadOfBreakingIt) {
  Fixture f;
  const std::string id = f.field_at_revision_2();
  Gate gate;
  Result<nlohmann::json> held = Status(StatusCode::kInternal, "not run");
  std::thread holder([&] { held = f.fields->remove_last_curve(id, gate); });
  gate.wait_entered();
  std::atomic<bool> deleted{false};
  Status removed;
  std::thread deleter([&] {
    removed = f.fields->remove(id, null_interrupter());
    deleted = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  EXPECT_FALSE(deleted.load()) << "the delete did not wait for the undo";
  gate.release();
  holder.join();
  deleter.join();
  // The undo wrote its revision and answered it; then the field was deleted, whole.
  ASSERT_TRUE(held.is_ok()) << held.status().to_string();
  EXPECT_EQ((*held)["revision"], 3);
  EXPECT_TRUE(removed.is_ok()) << removed.to_string();
  EXPECT_EQ(f.fields->get(id).status().code(), StatusCode::kNotFound);
  EXPECT_FALSE(fs::exists(f.store->path(ResourceKind::kField, id)));
  // Changes that were waiting find no field.
  EXPECT_EQ(f.fields->add_curve(id, kCurve3, null_interrupter()).status().code(), StatusCode::kNotFound);
}

// Two replicas on one store change one field at once: the revision's files are write-once, so
// the one that writes revision N second answers 409 naming "revision" and writes nothing; the
// winner's curve stands and the loser can retry on the new revision.
TEST(FieldService, OfTwoReplicasWritingTheSameRevisionTheSecondAnswers409) {
  Fixture f;
  auto created = f.fields->create(kSketch, null_interrupter());
  ASSERT_TRUE(created.is_ok()) << created.status().to_string();
  const std::string id = (*created)["id"];
  FieldService other(*f.store, f.config);  // a second replica on the same store
  ASSERT_TRUE(other.start(nullptr).is_ok());
  ASSERT_EQ(other.get(id).value()["revision"], 1);
  Gate gate;
  Result<nlohmann::json> slow = Status(StatusCode::kInternal, "not run");
  std::thread replica_a([&] { slow = f.fields->add_curve(id, kCurve2, gate); });
  gate.wait_entered();  // A works on revision 2 (its solve polls the gate)
  auto fast = other.add_curve(id, kCurve3, null_interrupter());
  ASSERT_TRUE(fast.is_ok()) << fast.status().to_string();
  EXPECT_EQ((*fast)["revision"], 2);
  const auto winner = f.store->read(ResourceKind::kField, id, "r2.stf").value();
  gate.release();
  replica_a.join();
  ASSERT_FALSE(slow.is_ok());
  EXPECT_EQ(slow.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(slow.status().field(), "revision");
  EXPECT_EQ(f.store->read(ResourceKind::kField, id, "r2.stf").value(), winner);
  EXPECT_FALSE(f.has_file(id, "r3.stf"));
  // The loser sees the winner's revision and its retry becomes revision 3.
  EXPECT_EQ(f.revision(id), 2);
  auto retried = f.fields->add_curve(id, kCurve2, null_interrupter(), 2);
  ASSERT_TRUE(retried.is_ok()) << retried.status().to_string();
  EXPECT_EQ((*retried)["revision"], 3);
}

// A writer that died between a revision's .stf and its .json leaves the .stf alone: the next
// change is refused while it may still be a write in progress, then takes the number back.
TEST(FieldService, ARevisionLeftBehalfWrittenIsTakenBackOnceOld) {
  Fixture f;
  const std::string id = f.field_at_revision_2();
  const fs::path leftover = f.store->path(ResourceKind::kField, id, "r3.stf");
  fs::copy_file(f.store->path(ResourceKind::kField, id, "r2.stf"), leftover);
  auto refused = f.fields->add_curve(id, kCurve3, null_interrupter());
  ASSERT_FALSE(refused.is_ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(refused.status().field(), "revision");
  fs::last_write_time(leftover, fs::file_time_type::clock::now() - std::chrono::minutes(5));
  auto added = f.fields->add_curve(id, kCurve3, null_interrupter());
  ASSERT_TRUE(added.is_ok()) << added.status().to_string();
  EXPECT_EQ((*added)["revision"], 3);
  EXPECT_TRUE(f.has_file(id, "r3.json"));
}

}  // namespace
}  // namespace solidtex::server
