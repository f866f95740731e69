#include "worker_pool.h"

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace solidtex::server {
namespace {

// A gate tasks wait on until the test opens it.
struct Gate {
  std::mutex m;
  std::condition_variable cv;
  bool open = false;
  void wait() {
    std::unique_lock<std::mutex> l(m);
    cv.wait(l, [&] { return open; });
  }
  void release() {
    {
      std::lock_guard<std::mutex> g(m);
      open = true;
    }
    cv.notify_all();
  }
};

TEST(WorkerPool, RejectsAtOnceWhenTheQueueIsFullAndDrainsOnShutdown) {
  WorkerPool pool(1, 2);
  Gate gate;
  std::atomic<int> done{0};
  ASSERT_TRUE(pool.try_submit([&] { gate.wait(); ++done; }));
  // Wait until the worker took the first task, so the queue is empty again.
  for (int i = 0; i < 200 && pool.running() == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(pool.running(), 1);
  EXPECT_TRUE(pool.try_submit([&] { ++done; }));
  EXPECT_TRUE(pool.try_submit([&] { ++done; }));
  EXPECT_EQ(pool.queued(), 2);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(pool.try_submit([&] { ++done; }));  // full: refused without blocking
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(100));
  gate.release();
  pool.shutdown();
  EXPECT_EQ(done.load(), 3);
  EXPECT_FALSE(pool.try_submit([&] { ++done; }));  // stopped
  EXPECT_EQ(done.load(), 3);
}

TEST(WorkerPool, RunsTasksOnSeveralWorkersAtOnce) {
  WorkerPool pool(2, 4);
  Gate gate;
  std::atomic<int> started{0};
  for (int i = 0; i < 2; ++i) ASSERT_TRUE(pool.try_submit([&] { ++started; gate.wait(); }));
  for (int i = 0; i < 200 && started.load() < 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(started.load(), 2);
  gate.release();
}

}  // namespace
}  // namespace solidtex::server
