// The one place for thread counts and the one thread pool of OpenABLE.
//
// Work is spread over std::threads started for the call rather than over OpenCV's
// cv::parallel_for_: its pool has one process-wide size (cv::setNumThreads), while every
// OpenABLE stage takes its own count (the Threads key, the `threads` argument of the library
// calls, 0 = all cores), and a library must not change a global setting of its host program.
#pragma once

#include <functional>

namespace openable {

// `threads` itself when > 0; otherwise the number of cores (at least 1).
int EffectiveThreads(int threads);

// Runs body(t) for t = 0 .. count - 1, each on its own thread (t = 0 on the calling thread),
// and waits for all. The first exception a body throws is rethrown once every body has ended.
void RunOnThreads(int count, const std::function<void(int)>& body);

// Runs body(i) for every i in [0, count) on min(EffectiveThreads(threads), count) threads,
// handing indices out one at a time in increasing order (items of unequal cost balance
// themselves). After a body throws, no further index is started; the first exception is
// rethrown once the threads have ended.
//
// Between items the calling thread runs the interrupt check (SetInterruptCheck) at most every
// 50 ms; an exception it throws stops the loop like one thrown by a body.
void ParallelFor(int count, int threads, const std::function<void(int)>& body);

// A check a host installs so that long computations stop when the user asks (the Python module:
// Ctrl-C, which Python only notices between bytecodes, while the computation runs in C++). It
// throws to stop the computation; nullptr removes it. Called on the thread that started the
// loop only (ParallelFor), never from a signal handler.
using InterruptCheck = void (*)();
void SetInterruptCheck(InterruptCheck check);

// Runs the installed interrupt check now (nothing when none is installed): for loops of long
// steps that do not go through ParallelFor (the runs of a sweep).
void CheckForInterrupt();

}  // namespace openable
