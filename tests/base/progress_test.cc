// Progress lines: redrawn in place on a terminal, and in a log (a file, a pipe) one line per
// interval of the reporter's clock and a final line, whatever the number of updates.
#include "OpenABLE/base/progress.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <sstream>
#include <string>

namespace openable {
namespace {

using std::chrono::milliseconds;

// A reporter on a simulated clock that the test moves by hand.
struct Simulated {
  explicit Simulated(bool terminal) : reporter(out, true, terminal) {
    reporter.SetClock([this] { return now; });
  }
  std::ostringstream out;
  ProgressReporter::Clock::time_point now{};
  ProgressReporter reporter;
};

int Count(const std::string& text, char c) {
  return static_cast<int>(std::count(text.begin(), text.end(), c));
}

TEST(Progress, LogWritesOneLinePerIntervalNotOnePerUpdate) {
  // 60 s of work in 6000 updates, one every 10 ms: a line at 5, 10, ..., 55 s (11 lines; the
  // 60 s mark is the last update, which End() reports) plus the final line.
  Simulated s(false);
  s.reporter.Begin("describing", 6000, "frames");
  for (int done = 1; done <= 6000; ++done) {
    s.now += milliseconds(10);
    s.reporter.Update(done);
  }
  s.reporter.End();
  const std::string log = s.out.str();
  EXPECT_EQ(Count(log, '\n'), 12) << log;
  EXPECT_EQ(Count(log, '\r'), 0) << log;  // no redraws in a log
  EXPECT_NE(log.find("describing  500/6000 frames (  8%)  5.0 s, about 55 s left\n"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("6000/6000 frames (100%)  60.0 s\n"), std::string::npos) << log;
}

TEST(Progress, ShortStageInALogWritesItsFinalLineOnly) {
  Simulated s(false);
  s.reporter.Begin("matching", 100, "rows");
  for (int done = 1; done <= 100; ++done) {
    s.now += milliseconds(40);  // 4 s in all: under the 5 s interval
    s.reporter.Update(done);
  }
  s.reporter.End();
  EXPECT_EQ(Count(s.out.str(), '\n'), 1) << s.out.str();
}

TEST(Progress, TerminalRedrawsAtMostTenTimesASecond) {
  Simulated s(true);
  s.reporter.Begin("describing", 1000, "frames");
  for (int done = 1; done <= 1000; ++done) {
    s.now += milliseconds(2);  // 2 s in all
    s.reporter.Update(done);
  }
  s.reporter.End();
  const std::string screen = s.out.str();
  const int redraws = Count(screen, '\r');
  EXPECT_GE(redraws, 19) << screen;  // one per 100 ms over 2 s, the last update, the final line
  EXPECT_LE(redraws, 22) << screen;
  EXPECT_EQ(Count(screen, '\n'), 1) << screen;  // only the final line ends a line
}

}  // namespace
}  // namespace openable
