// Outputs of a run: the matrix as text, as float32 .npy and as colour PNG images.
//
// Every file is first written beside its destination under a temporary name and renamed
// only when all outputs of the run were written (OutputBatch), so a failed run never leaves
// a half-written file, nor a set of outputs that looks complete but is not.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "matching/bounded.h"

namespace openable {

// The 12 colour maps of the original OpenABLE (docs/output_formats.md). Pixel of a
// normalised distance s in [0, 1], as (blue, green, red) in [0, 1]; multiplied by 255 and
// rounded. Throws std::logic_error for a map outside 0-11.
cv::Vec3f ColorOf(float s, int map);
cv::Mat3b ColorizeMatrix(const cv::Mat1f& normalized, int map);

// Bytes of a NumPy .npy file (format version 1.0, little-endian float32, C order) holding
// `m` (CV_32FC1).
std::string EncodeNpy(const cv::Mat1f& m);
// The header alone (magic, version, dictionary) of a rows x cols float32 .npy; the data
// follows it in C order.
std::string NpyHeader(int rows, int cols);

// Text of the matrix: one row per line, values separated by one space. Floats are written
// with 6 significant digits; CV_8U matrices (thresholded) as integers.
std::string EncodeText(const cv::Mat& m);

// The same text in pieces of a few hundred rows, each formatted in parallel when asked for,
// for writing a large matrix without holding its whole text (OutputBatch::Stage with a
// producer). `m` must outlive the object.
class TextChunks {
 public:
  explicit TextChunks(const cv::Mat& m);
  // The next piece (valid until the next call); false when the text is done.
  bool Next(std::string_view& piece);

 private:
  cv::Mat m_;
  int next_row_ = 0;
  std::vector<std::string> parts_;
  std::string chunk_;
};

// Bytes of a PNG image (OpenCV's encoder).
std::string EncodePng(const cv::Mat& image);

// Bytes of the matches file: .npy (structured array: query, reference int32; distance
// float32; rank int32; score float32) or .csv (header "query,reference,distance,rank,score").
std::string EncodeMatches(const std::vector<Match>& matches, bool csv);


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
