// The bounded pool that runs synthesis and other heavy requests, so HTTP I/O threads never do.
// `workers` threads take tasks from a TBB concurrent_bounded_queue of capacity `queue`:
// try_submit() never blocks; it fails at once when `queue` tasks are already waiting (the
// server answers 503 + Retry-After) or the pool is shutting down. Tasks themselves may use TBB
// parallelism (the synthesizer does). `when_idle`, if given, runs on the worker that finishes
// the last running task while none is queued (the server returns freed memory to the system
// there). Thread-safe.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <thread>
#include <vector>

namespace solidtex::server {

class WorkerPool {
 public:
  using Task = std::function<void()>;
  WorkerPool(int workers, int queue_capacity, Task when_idle = {});
  ~WorkerPool();  // shutdown()
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  bool try_submit(Task task);
  // Stops accepting, runs every task already queued, joins the workers. Idempotent.
  void shutdown();

  int queued() const { return queued_.load(); }
  int running() const { return running_.load(); }
  int workers() const { return int(threads_.size()); }
  int capacity() const { return capacity_; }

 private:
  struct Queue;
  void work();
  std::unique_ptr<Queue> queue_;
  std::vector<std::thread> threads_;
  std::atomic<int> queued_{0};
  std::atomic<int> running_{0};
  std::atomic<bool> stopping_{false};
  int capacity_;
  Task when_idle_;
};

}  // namespace solidtex::server
