// Ties a long operation's Interrupter to an HTTP request: it interrupts once the request's
// deadline has passed (measured from arrival, so time spent queued counts) or the client has
// disconnected, or the server is shutting down. Thread-safe (synthesis polls it from TBB workers).
#pragma once

#include <atomic>
#include <chrono>
#include <memory>

#include "core/interrupter.h"
#include "core/status.h"

namespace solidtex::server {

using Clock = std::chrono::steady_clock;

class RequestInterrupter : public Interrupter {
 public:
  RequestInterrupter(Clock::time_point deadline, std::shared_ptr<const std::atomic<bool>> disconnected,
                     const std::atomic<bool>* shutting_down = nullptr)
      : deadline_(deadline), disconnected_(std::move(disconnected)), shutting_down_(shutting_down) {}

  bool was_interrupted(int percent = -1) override {
    if (percent >= 0) percent_.store(percent);
    return deadline_passed() || client_gone() || (shutting_down_ && shutting_down_->load());
  }
  bool deadline_passed() const { return Clock::now() >= deadline_; }
  bool client_gone() const { return disconnected_ && disconnected_->load(); }
  int percent() const { return percent_.load(); }

  // What a cancelled operation should report: 504 past the deadline, else cancelled.
  Status interruption_status(const std::string& what) const {
    if (deadline_passed())
      return Status(StatusCode::kDeadlineExceeded, what + " did not finish before the request's deadline", "timeout");
    if (client_gone()) return Status(StatusCode::kCancelled, what + " cancelled: the client disconnected");
    return Status(StatusCode::kCancelled, what + " cancelled: the server is shutting down");
  }

 private:
  Clock::time_point deadline_;
  std::shared_ptr<const std::atomic<bool>> disconnected_;
  const std::atomic<bool>* shutting_down_;
  std::atomic<int> percent_{0};
};

}  // namespace solidtex::server
