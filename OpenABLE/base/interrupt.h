// Interrupted runs: temporary files that must not outlive the process.
//
// A program calls InstallInterruptCleanup once. From then on SIGINT, SIGTERM and SIGHUP remove
// every registered temporary file (unlink, from the handler: async-signal-safe calls only),
// print one line "<program>: interrupted by SIGTERM (temporary files removed)" on stderr and end
// the process with status 128 + signal number (130 for SIGINT, 143 for SIGTERM, 129 for SIGHUP).
// SIGKILL cannot be caught: temporaries are named so that they cannot be taken for outputs
// (OutputBatch: ".<name>.tmp-<pid>-<n>") and a later run removes stale ones (exports.h).
#pragma once

#include <string>

namespace openable {

// Installs the handlers for SIGINT, SIGTERM and SIGHUP. `program` (kept, not copied) prefixes
// the message.
void InstallInterruptCleanup(const char* program);

// From now on an interruption still removes the temporary files and ends the process with
// 128 + signal, but prints nothing: for the processes other than the first under mpirun, which
// speak through process 0 (cluster.h). mpirun ends them with SIGTERM when the run stops on
// Ctrl-C or when process 0 has already reported a failure and exited; one line from process 0
// (or none) is what the user should see, not one per process.
void SilenceInterruptMessage();

// What an interruption now leaves besides the removed temporaries, said in its line:
// "<program>: interrupted by SIGINT (temporary files removed; <note>)", e.g. "route.map
// unchanged" before a file is replaced and "route.map holds session winter" after. Empty: no
// note. Call from one thread at a time (the handler reads it without a lock).
void SetInterruptNote(const std::string& note);
// The note the next OutputBatch::Commit sets once its files are in place, while signals are
// still deferred: an interruption just after a file was replaced never reports its old state.
// A commit that fails drops it.
void SetInterruptNoteOnCommit(const std::string& note);
// The note of SetInterruptNoteOnCommit, taken (empty when none): for OutputBatch::Commit.
std::string TakeInterruptNoteOnCommit();

// Registers a file to remove if the process is interrupted. Returns a slot for
// UnregisterTemporary, or -1 when every slot is taken (the file is then only removed by the
// owner or by a later run's stale-file sweep).
int RegisterTemporary(const std::string& path);
void UnregisterTemporary(int slot);

// While an InterruptDeferral lives (OutputBatch::Commit), a signal is recorded instead of
// acted on; when the last deferral ends, a recorded signal is acted on (cleanup, message,
// exit). This keeps a commit from being cut between two renames.
class InterruptDeferral {
 public:
  InterruptDeferral();
  ~InterruptDeferral();
  InterruptDeferral(const InterruptDeferral&) = delete;
  InterruptDeferral& operator=(const InterruptDeferral&) = delete;
};

}  // namespace openable
