// Progress of long stages on a terminal or a log: "describing 1200/3576 frames (33%)".
#pragma once

#include <chrono>
#include <cstdint>
#include <iosfwd>
#include <string>

namespace openable {

class ProgressReporter {
 public:
  // Writes to `out` when `enabled`. On a terminal the line is redrawn in place (at most
  // 10 times a second); otherwise one line is written per 10% step, so logs stay short.
  // Stages shorter than two seconds print only their final line in log mode.
  ProgressReporter(std::ostream& out, bool enabled, bool terminal);
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
  bool pending_ = false;  // a terminal line is drawn without its newline
  std::string what_, unit_;
  std::int64_t total_ = 0;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_print_;
};

// Wall time since `start`, in seconds (the timings of the reports).
inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// True when file descriptor `fd` is a terminal.
bool IsTerminal(int fd);

}  // namespace openable
