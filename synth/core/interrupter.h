// Progress reporting and cancellation for long operations, modelled on OpenVDB's
// NullInterrupter. Operations call start(), then was_interrupted(percent) often, then end().
// Thread-safety: was_interrupted() may be called from several worker threads at once;
// implementations must tolerate that (the default one is trivially safe).
#pragma once

#include <algorithm>
#include <atomic>
#include <mutex>

namespace solidtex {

class Interrupter {
 public:
  virtual ~Interrupter() = default;
  virtual void start(const char* /*task_name*/) {}
  virtual void end() {}
  // `percent` in [0, 100] or -1 when unknown. Returning true asks the operation to stop
  // as soon as it can; it then returns StatusCode::kCancelled (or kDeadlineExceeded).
  virtual bool was_interrupted(int /*percent*/ = -1) { return false; }
};

// The default: never interrupts, reports nothing.
inline Interrupter& null_interrupter() {
  static Interrupter instance;
  return instance;
}

// Shares one interrupter among worker threads: calls are serialised, and once it has asked to
// stop, every later poll answers true without asking again.
class LatchedInterrupter {
 public:
  explicit LatchedInterrupter(Interrupter& i) : interrupter_(i) {}
  bool poll(int percent = -1) {
    if (stop_.load(std::memory_order_relaxed)) return true;
    std::lock_guard<std::mutex> g(mutex_);
    if (interrupter_.was_interrupted(std::clamp(percent, -1, 100))) stop_ = true;
    return stop_;
  }
  bool stopped() const { return stop_.load(); }

 private:
  Interrupter& interrupter_;
  std::mutex mutex_;
  std::atomic<bool> stop_{false};
};

}  // namespace solidtex
