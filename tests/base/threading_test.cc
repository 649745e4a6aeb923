// ParallelFor's interrupt check (OpenABLE/base/threading.h): what the Python module relies on
// for Ctrl-C. Item counts are asserted, not times.
#include "OpenABLE/base/threading.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

namespace openable {
namespace {

std::atomic<int> g_checks{0};

void StopAtOnce() {
  ++g_checks;
  throw std::runtime_error("interrupted");
}

void NeverStop() { ++g_checks; }

// A check that throws stops the loop: no item starts after it, the exception reaches the caller.
TEST(ParallelFor, AThrowingInterruptCheckStopsTheLoop) {
  SetInterruptCheck(&StopAtOnce);
  g_checks = 0;
  std::atomic<int> done{0};
  constexpr int kItems = 200;  // 20 ms each: far longer than the 50 ms between checks
  EXPECT_THROW(ParallelFor(kItems, 2,
                           [&](int) {
                             std::this_thread::sleep_for(std::chrono::milliseconds(20));
                             ++done;
                           }),
               std::runtime_error);
  SetInterruptCheck(nullptr);
  EXPECT_EQ(g_checks.load(), 1);
  EXPECT_LT(done.load(), kItems);
  EXPECT_GT(done.load(), 0);
}

// A check that does not throw changes nothing; without a check, CheckForInterrupt does nothing.
TEST(ParallelFor, AQuietInterruptCheckLetsEveryItemRun) {
  SetInterruptCheck(&NeverStop);
  g_checks = 0;
  std::atomic<int> done{0};
  ParallelFor(30, 2, [&](int) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ++done;
  });
  EXPECT_EQ(done.load(), 30);
  EXPECT_GE(g_checks.load(), 1);
  CheckForInterrupt();
  EXPECT_GE(g_checks.load(), 2);
  SetInterruptCheck(nullptr);
  EXPECT_NO_THROW(CheckForInterrupt());
}

}  // namespace
}  // namespace openable
