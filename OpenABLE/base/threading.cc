#include "OpenABLE/base/threading.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace openable {

int EffectiveThreads(int threads) {
  if (threads > 0) return threads;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

void RunOnThreads(int count, const std::function<void(int)>& body) {
  std::exception_ptr error;
  std::mutex error_mutex;
  auto run = [&](int t) {
    try {
      body(t);
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < count; ++t) pool.emplace_back(run, t);
  if (count > 0) run(0);
  for (auto& thread : pool) thread.join();
  if (error) std::rethrow_exception(error);
}

namespace {
std::atomic<InterruptCheck> g_interrupt_check{nullptr};
}  // namespace

void SetInterruptCheck(InterruptCheck check) { g_interrupt_check = check; }

void CheckForInterrupt() {
  if (const InterruptCheck check = g_interrupt_check.load()) check();
}

void ParallelFor(int count, int threads, const std::function<void(int)>& body) {
  if (count <= 0) return;
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  const InterruptCheck check = g_interrupt_check.load();
  RunOnThreads(std::min(EffectiveThreads(threads), count), [&](int t) {
    auto last_check = std::chrono::steady_clock::now();
    for (int i = next++; i < count && !failed; i = next++) {
      try {
        if (check != nullptr && t == 0) {
          const auto now = std::chrono::steady_clock::now();
          if (now - last_check >= std::chrono::milliseconds(50)) {
            last_check = now;
            check();
          }
        }
        body(i);
      } catch (...) {
        failed = true;
        throw;
      }
    }
  });
}

}  // namespace openable
