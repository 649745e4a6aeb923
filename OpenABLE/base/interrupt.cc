#include "OpenABLE/base/interrupt.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstring>
#include <string>

namespace openable {
namespace {

// Fixed storage: the handler may not allocate. A slot is usable by the handler once its
// state is kFull (stored after the path, with release order).
constexpr int kSlots = 64;
constexpr size_t kPathMax = 4096;
enum : int { kFree = 0, kClaimed = 1, kFull = 2 };
char g_paths[kSlots][kPathMax];
std::atomic<int> g_state[kSlots];
std::atomic<int> g_deferrals{0};
std::atomic<int> g_pending{0};
const char* g_program = "OpenABLE";
std::atomic<bool> g_silent{false};
// The note of SetInterruptNote: two buffers, the one in use named by g_note (-1: none), so that
// the handler never reads a buffer being written.
constexpr size_t kNoteMax = 4096;
char g_notes[2][kNoteMax];
std::atomic<int> g_note{-1};
static_assert(std::atomic<int>::is_always_lock_free, "the handler needs lock-free atomics");

void Write(const char* s) {
  const ssize_t unused = ::write(2, s, std::strlen(s));
  (void)unused;
}

const char* SignalName(int sig) {
  switch (sig) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    default:
      return "a signal";
  }
}

[[noreturn]] void CleanUpAndExit(int sig) {
  for (int k = 0; k < kSlots; ++k)
    if (g_state[k].load(std::memory_order_acquire) == kFull) ::unlink(g_paths[k]);
  if (g_silent.load()) ::_exit(128 + sig);
  if (::isatty(2)) Write("\n");  // after a progress line redrawn in place
  Write(g_program);
  Write(": interrupted by ");
  Write(SignalName(sig));
  Write(" (temporary files removed");
  const int note = g_note.load(std::memory_order_acquire);
  if (note >= 0) {
    Write("; ");
    Write(g_notes[note]);
  }
  Write(")\n");
  ::_exit(128 + sig);
}

void Handler(int sig) {
  if (g_deferrals.load() > 0) {
    g_pending.store(sig);
    return;
  }
  CleanUpAndExit(sig);
}

}  // namespace

void InstallInterruptCleanup(const char* program) {
  g_program = program;
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = Handler;
  sigemptyset(&sa.sa_mask);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&sa.sa_mask, sig);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaction(sig, &sa, nullptr);
}

void SilenceInterruptMessage() { g_silent.store(true); }

void SetInterruptNote(const std::string& note) {
  if (note.empty()) {
    g_note.store(-1, std::memory_order_release);
    return;
  }
  const int next = g_note.load(std::memory_order_acquire) == 0 ? 1 : 0;
  const size_t n = std::min(note.size(), kNoteMax - 1);
  std::memcpy(g_notes[next], note.data(), n);
  g_notes[next][n] = '\0';
  g_note.store(next, std::memory_order_release);
}

namespace {
std::string g_note_on_commit;  // read and written outside the handler only
}  // namespace

void SetInterruptNoteOnCommit(const std::string& note) { g_note_on_commit = note; }

std::string TakeInterruptNoteOnCommit() {
  std::string note;
  note.swap(g_note_on_commit);
  return note;
}

int RegisterTemporary(const std::string& path) {
  if (path.size() >= kPathMax) return -1;
  for (int k = 0; k < kSlots; ++k) {
    int expected = kFree;
    if (g_state[k].compare_exchange_strong(expected, kClaimed)) {
      std::memcpy(g_paths[k], path.c_str(), path.size() + 1);
      g_state[k].store(kFull, std::memory_order_release);
      return k;
    }
  }
  return -1;
}

void UnregisterTemporary(int slot) {
  if (slot >= 0 && slot < kSlots) g_state[slot].store(kFree, std::memory_order_release);
}

InterruptDeferral::InterruptDeferral() { ++g_deferrals; }

InterruptDeferral::~InterruptDeferral() {
  if (--g_deferrals == 0) {
    const int sig = g_pending.exchange(0);
    if (sig != 0) CleanUpAndExit(sig);
  }
}

}  // namespace openable
