#include "OpenABLE/base/threading.h"

#include <algorithm>
#include <atomic>
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

void ParallelFor(int count, int threads, const std::function<void(int)>& body) {
  if (count <= 0) return;
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  RunOnThreads(std::min(EffectiveThreads(threads), count), [&](int) {
    for (int i = next++; i < count && !failed; i = next++) {
      try {
        body(i);
      } catch (...) {
        failed = true;
        throw;
      }
    }
  });
}

}  // namespace openable
