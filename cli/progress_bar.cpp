#include "progress_bar.h"

#include <unistd.h>

#include <csignal>
#include <cstdio>

namespace solidtex::cli {
namespace {
std::atomic<bool> g_sigint{false};
extern "C" void on_sigint(int) { g_sigint = true; }
}  // namespace

ProgressBar::ProgressBar() : tty_(::isatty(STDERR_FILENO) == 1) { std::signal(SIGINT, on_sigint); }

void ProgressBar::start(const char* task_name) {
  task_ = task_name;
  last_percent_ = -1;
}

void ProgressBar::end() {
  if (tty_ && last_percent_ >= 0) std::fprintf(stderr, "\r%-60s\r", "");
}

bool ProgressBar::was_interrupted(int percent) {
  if (tty_ && percent >= 0 && percent != last_percent_) {
    last_percent_ = percent;
    const int width = 30, filled = percent * width / 100;
    std::fprintf(stderr, "\r%s [%.*s%*s] %3d%%", task_.c_str(), filled, "==============================",
                 width - filled, "", percent);
    std::fflush(stderr);
  }
  return g_sigint.load();
}

}  // namespace solidtex::cli
