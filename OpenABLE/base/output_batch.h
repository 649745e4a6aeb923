// Outputs written all or nothing: every file is first written beside its destination under a
// temporary name and renamed only when all outputs of the run were written (OutputBatch), so a
// failed run never leaves a half-written file, nor a set of outputs that looks complete but is
// not.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace openable {

// Stages files and commits them together (docs/output_formats.md, "Temporaries and
// interrupted runs").
//  - A file is staged as ".<name>.tmp-<pid>-<n>" beside its destination: hidden, and with a
//    name no consumer takes for an output. It is registered for removal on SIGINT/SIGTERM/
//    SIGHUP (interrupt.h) and removed by the destructor when not committed.
//  - Staging a file first removes stale temporaries and backups of the same destination
//    (".<name>.tmp-<pid>-*", ".<name>.old-<pid>-*") left by a process that no longer runs
//    (a run killed with SIGKILL, or a power cut).
//  - Commit renames every staged file into place. An existing destination is first
//    hard-linked to ".<name>.old-<pid>-<n>"; if a rename fails part-way, the files already
//    renamed are put back (the old file restored from its backup, or removed when there was
//    none), so the destinations hold either the whole new batch or the whole old state.
//    Signals are deferred during Commit (interrupt.h).
// The outputs of one run must be distinct files: two keys naming the same file would leave one
// output silently overwritten by the other. `outputs` are (key, path) pairs; paths are compared
// after making them absolute and resolving ".", ".." and existing links. Throws InputError
// "<key>: "<path>" is also the file of <other key> ..." naming both keys.
void CheckDistinctOutputs(const std::vector<std::pair<std::string, std::string>>& outputs);

// An output prefix (Evaluation_name, openable_sweep --output, Snaps_output_name): the files
// are <prefix>.json, <prefix>_pr.png, ..., so a prefix that is a folder (or ends with '/')
// would write hidden files in it. Throws InputError naming `key` and the prefix.
void CheckOutputPrefix(const std::string& key, const std::string& prefix);

class OutputBatch {
 public:
  OutputBatch() = default;
  OutputBatch(const OutputBatch&) = delete;
  OutputBatch& operator=(const OutputBatch&) = delete;
  // Removes every staged temporary file not yet committed.
  ~OutputBatch();
  // Writes `bytes` to a temporary file beside `path`, creating its folder when missing.
  // Throws InputError naming `key`, the path and the system's reason (e.g. "No space left on
  // device") when the file cannot be written; the partial temporary is removed; and naming
  // both keys when `path` is a file already staged in this batch (CheckDistinctOutputs).
  void Stage(const std::string& key, const std::string& path, const std::string& bytes);
  // The same for a file made of several pieces written one after the other (no copy into
  // one buffer: a matrix's rows can be written from where they are).
  void Stage(const std::string& key, const std::string& path,
             const std::vector<std::string_view>& parts);
  // The same for a file whose pieces are produced while it is written: next(piece) sets the
  // next piece (valid until the following call) and returns false when there is none.
  void Stage(const std::string& key, const std::string& path,
             const std::function<bool(std::string_view&)>& next);
  // Renames every staged file to its destination, all or nothing (see above). Throws
  // InputError naming the key and path whose rename failed.
  void Commit();
  // Destinations staged so far.
  std::vector<std::string> Paths() const;

 private:
  struct Item {
    std::string key, temp, path;
    int slot = -1;  // RegisterTemporary
  };
  std::vector<Item> items_;
};

// Test hook: once `bytes` bytes have been written by OutputBatch::Stage in this process,
// further writes fail with `error` (e.g. ENOSPC). -1 turns it off (the default).
void FailStagedWritesAfterForTesting(long long bytes, int error);

}  // namespace openable
