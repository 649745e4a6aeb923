#include "OpenABLE/base/progress.h"

#include <unistd.h>

#include <cstdio>
#include <ostream>
#include <utility>

namespace openable {

bool IsTerminal(int fd) { return ::isatty(fd) == 1; }

ProgressReporter::ProgressReporter(std::ostream& out, bool enabled, bool terminal,
                                   std::chrono::milliseconds log_interval)
    : out_(out), enabled_(enabled), terminal_(terminal), log_interval_(log_interval) {}

void ProgressReporter::SetClock(std::function<Clock::time_point()> clock) {
  clock_ = std::move(clock);
}

ProgressReporter::~ProgressReporter() {
  if (pending_) out_ << "\r\x1b[K" << std::flush;
}

void ProgressReporter::Begin(const std::string& what, std::int64_t total, const std::string& unit) {
  what_ = what;
  unit_ = unit;
  total_ = total;
  start_ = last_print_ = clock_();
}

void ProgressReporter::Update(std::int64_t done) {
  if (!enabled_ || total_ <= 0) return;
  const auto now = clock_();
  if (terminal_) {
    if (now - last_print_ < std::chrono::milliseconds(100) && done < total_) return;
  } else {
    // End() writes the final line; in between, one line per interval.
    if (done >= total_ || now - last_print_ < log_interval_) return;
  }
  last_print_ = now;
  Print(done, false);
}

void ProgressReporter::End() {
  if (!enabled_) return;
  Print(total_, true);
}

void ProgressReporter::Print(std::int64_t done, bool final) {
  const double elapsed = std::chrono::duration<double>(clock_() - start_).count();
  char line[256];
  const double percent = total_ > 0 ? 100.0 * static_cast<double>(done) / total_ : 100.0;
  int n = std::snprintf(line, sizeof line, "  %-11s %lld/%lld %s (%3.0f%%)  %.1f s", what_.c_str(),
                        static_cast<long long>(done), static_cast<long long>(total_), unit_.c_str(),
                        percent, elapsed);
  if (!final && done > 0 && done < total_) {
    const double left = elapsed * static_cast<double>(total_ - done) / static_cast<double>(done);
    n += std::snprintf(line + n, sizeof line - n, ", about %.0f s left", left);
  }
  if (terminal_) {
    out_ << "\r" << line << "\x1b[K" << (final ? "\n" : "") << std::flush;
    pending_ = !final;
  } else {
    out_ << line << "\n" << std::flush;
  }
}

}  // namespace openable
