// What every command-line program of OpenABLE does around its work: the exit statuses
// (docs/output_formats.md, "Exit status") and the one place that maps errors to them.
#pragma once

#include <functional>
#include <string>

namespace openable {

inline constexpr int kExitSuccess = 0;
inline constexpr int kExitInputError = 1;     // bad configuration, input data or output path
inline constexpr int kExitUsageError = 2;     // bad command line
inline constexpr int kExitInternalError = 3;  // a bug: a broken internal precondition

// Runs `body` and returns its status; an InputError becomes one line
// "<program>: error: <message>" on stderr and status 1, any other exception
// "<program>: internal error (please report): <message>" and status 3. The message is shown
// by ToValidUtf8 (strings.h), as every line the programs print: a path in another encoding
// quoted raw by a message has its invalid bytes written \xNN.
int RunProgram(const std::string& program, const std::function<int()>& body);

// For programs that describe frames one after the other (Test_OpenABLE, openable_sweep): every
// frame passes through buffers of several MB (a 960x540 colour frame as float is 6 MB), which
// glibc serves with mmap and returns at free, so each frame paid for fresh zeroed pages.
// Keeping blocks up to 256 MB on the heap lets them be reused (docs/benchmarks.md, "End-to-end
// run times and start-up"). Call first in main.
void KeepFrameBuffersOnTheHeap();

}  // namespace openable
