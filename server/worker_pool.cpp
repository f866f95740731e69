#include "worker_pool.h"

#include <tbb/concurrent_queue.h>

#include <mutex>

namespace solidtex::server {

struct WorkerPool::Queue {
  // Holds the tasks; an empty Task is the "exit" sentinel pushed at shutdown.
  tbb::concurrent_bounded_queue<Task> tasks;
  std::mutex submit_mutex;  // makes "check stopping, then push" atomic with shutdown()
};

WorkerPool::WorkerPool(int workers, int queue_capacity, Task when_idle)
    : queue_(std::make_unique<Queue>()), capacity_(queue_capacity), when_idle_(std::move(when_idle)) {
  // The sentinels need room too, so the TBB capacity is queue + workers; try_submit enforces
  // the user-visible capacity itself.
  queue_->tasks.set_capacity(std::ptrdiff_t(queue_capacity + workers));
  for (int i = 0; i < workers; ++i) threads_.emplace_back([this] { work(); });
}

WorkerPool::~WorkerPool() { shutdown(); }

bool WorkerPool::try_submit(Task task) {
  if (!task) return false;
  std::lock_guard<std::mutex> g(queue_->submit_mutex);
  if (stopping_.load()) return false;
  if (queued_.load() >= capacity_) return false;
  ++queued_;
  if (!queue_->tasks.try_push(std::move(task))) {
    --queued_;
    return false;
  }
  return true;
}

void WorkerPool::shutdown() {
  {
    std::lock_guard<std::mutex> g(queue_->submit_mutex);
    if (stopping_.exchange(true)) return;
  }
  // Queued tasks run first (FIFO), then each worker takes one sentinel and exits.
  for (size_t i = 0; i < threads_.size(); ++i) queue_->tasks.push(Task());
  for (auto& t : threads_) t.join();
}

void WorkerPool::work() {
  for (;;) {
    Task task;
    queue_->tasks.pop(task);
    if (!task) return;
    --queued_;
    ++running_;
    task();
    task = Task();  // the request's captures go before the idle hook runs
    if (--running_ == 0 && queued_.load() == 0 && when_idle_) when_idle_();
  }
}

}  // namespace solidtex::server
