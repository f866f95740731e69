// A terminal progress bar as an Interrupter: draws on stderr only when it is a terminal,
// and cancels on SIGINT (Ctrl-C) so long commands stop cleanly.
#pragma once

#include <atomic>
#include <string>

#include "core/interrupter.h"

namespace solidtex::cli {

class ProgressBar : public Interrupter {
 public:
  ProgressBar();
  void start(const char* task_name) override;
  void end() override;
  bool was_interrupted(int percent) override;

 private:
  bool tty_ = false;
  std::string task_;
  int last_percent_ = -1;
};

}  // namespace solidtex::cli
