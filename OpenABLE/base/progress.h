// Progress of long stages on a terminal or a log: "describing 1200/3576 frames (33%)".
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>

namespace openable {

class ProgressReporter {
 public:
  using Clock = std::chrono::steady_clock;
  // Writes to `out` when `enabled`. On a terminal the line is redrawn in place (at most
  // 10 times a second). Otherwise (a log file, a pipe, a CI console) one line is written every
  // `log_interval` (5 s) while a stage runs, then its final line: a stage shorter than that
  // writes its final line only, and a long one a line every few seconds, never one per frame.
  ProgressReporter(std::ostream& out, bool enabled, bool terminal,
                   std::chrono::milliseconds log_interval = std::chrono::seconds(5));
  // The clock the reporter reads (tests give a simulated one); steady_clock by default.
  void SetClock(std::function<Clock::time_point()> clock);
  // Clears a line left half-drawn on a terminal (a stage that ended by an error), so the
  // error that follows stands on its own line.
  ~ProgressReporter();
  ProgressReporter(const ProgressReporter&) = delete;
  ProgressReporter& operator=(const ProgressReporter&) = delete;
  // Starts a stage: `what` ("describing"), `total` items of `unit` ("frames").
  void Begin(const std::string& what, std::int64_t total, const std::string& unit);
  // `done` of the stage's items are finished. Cheap to call often.
  void Update(std::int64_t done);
  // Ends the stage with a final line giving its wall time.
  void End();

 private:
  void Print(std::int64_t done, bool final);
  std::ostream& out_;
  bool enabled_, terminal_;
  std::chrono::milliseconds log_interval_;
  std::function<Clock::time_point()> clock_ = [] { return Clock::now(); };
  bool pending_ = false;  // a terminal line is drawn without its newline
  std::string what_, unit_;
  std::int64_t total_ = 0;
  std::chrono::steady_clock::time_point start_, last_print_;
};

// Wall time since `start`, in seconds (the timings of the reports).
inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// True when file descriptor `fd` is a terminal.
bool IsTerminal(int fd);

}  // namespace openable
