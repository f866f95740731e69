// Progress reporting and cancellation for long operations, modelled on OpenVDB's
// NullInterrupter. Operations call start(), then was_interrupted(percent) often, then end().
// Thread-safety: was_interrupted() may be called from several worker threads at once;
// implementations must tolerate that (the default one is trivially safe).
#pragma once

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

}  // namespace solidtex
