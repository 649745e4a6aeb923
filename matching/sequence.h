// Sequence matching (ABLE; SeqSLAM's comparison of sequences of frames instead of single
// frames): S(i, j) = sum_{k = 0 .. L-1} D(i - k, j - k) forward, D(i - k, j + k) reverse (the
// reference route driven the other way). L = 1 gives single images, as the paper says (the
// original summed L + 1 terms). A sum never crosses from one traversal into another; the cells
// with fewer than L terms follow SequencePartial. One pass over the matrix whatever L (running
// sums in double, in place). docs/matching.md, "Sequences".
#pragma once

#include <limits>
#include <opencv2/core.hpp>
#include <vector>

#include "OpenABLE/base/enum_names.h"

namespace openable {

enum class SequenceDirection { kForward = 0, kReverse = 1, kBoth = 2 };  // kBoth: min of the two
OPENABLE_ENUM_NAMES(SequenceDirection, "forward", "reverse", "both")

// Checks the first frames of the traversals along one axis of `n` frames: increasing from 0,
// each below n (empty: one traversal). Throws std::logic_error "<what>: <value> is not valid;
// ..." otherwise (a ValueError in Python); `what` names the argument ("traversal_starts").
void CheckTraversalStarts(const std::vector<int>& starts, int n, const char* what);

// A cell with fewer than L terms (docs/matching.md, "Early frames"): scaled up to L terms, skipped
// (+inf), or the window of L frames ahead of it along its diagonal.
enum class SequencePartial { kScale, kSkip, kAhead };
OPENABLE_ENUM_NAMES(SequencePartial, "scale", "skip", "ahead")

// The terms of S(i, j) that exist: min(L, t + 1), t being the steps the diagonal can go back
// from (i, j) without leaving the traversal of i or that of j.
inline int SequenceTerms(int sequence_length, int steps_back) {
  return steps_back + 1 < sequence_length ? steps_back + 1 : sequence_length;
}

// The sum of `terms` single-frame distances scaled to L terms (L / terms, when terms < L) and
// rounded to float, or +inf for a partial sum with kSkip and kAhead (kAhead then replaces the
// cell by AheadShift's): how every sequence distance is finished, in the matrix sweep below
// and in SequenceCellDistance.
inline float ScaleSequenceSum(double sum, int terms, int sequence_length, SequencePartial partial) {
  if (terms == sequence_length) return static_cast<float>(sum);
  if (partial != SequencePartial::kScale) return std::numeric_limits<float>::infinity();
  return static_cast<float>(sum * sequence_length / terms);
}

// kAhead: a cell whose diagonal can go `steps_back` steps back and `steps_forward` steps
// forward without leaving the traversal of its row or that of its column takes the sum of the
// cell this many steps forward along the diagonal (0: the cell has its L terms itself); -1
// when the diagonal holds fewer than L frames in all (the cell is +inf).
inline int AheadShift(int sequence_length, int steps_back, int steps_forward) {
  if (steps_back >= sequence_length - 1) return 0;
  if (steps_back + steps_forward + 1 < sequence_length) return -1;
  return sequence_length - 1 - steps_back;
}

// S(q, j) of one cell, straight from descriptor rows, for searches that score a few cells
// (approximate candidates, the online detector): `queries` holds the query traversal (row q is
// frame q; with kAhead all of it, since an early cell reads frames after q) and `references`
// the reference traversal (row j is frame j); the terms are RowDistance
// (matching/distances.h) of (q - k, j - k), or (q - k, j + k) when `reverse`, for as many
// k < L as both traversals hold, summed in double and finished by ScaleSequenceSum (kAhead:
// the cell AheadShift steps forward). Equal to the cell of SequenceDistances up to float
// rounding (exactly for Hamming rows). `largest_term`, when given, is raised to the largest
// single-frame distance summed.
float SequenceCellDistance(const cv::Mat& queries, int q, const cv::Mat& references, int j,
                           int sequence_length, bool reverse, double* largest_term = nullptr,
                           SequencePartial partial = SequencePartial::kAhead);

// The sums of the sweep below one query row at a time, for searches whose query frames arrive
// in order (the online detector, a map's queries): S(q, .) of query frame q from its
// single-frame row D(q, .) and what the rows before it left, in O(columns) whatever L (the last
// L rows of D and the running sums of the previous row are kept). Forward diagonals; the query
// rows are one traversal (Restart begins another), the columns form traversals that no sum
// crosses (`col_starts`: a map's sessions). Cells with fewer than L terms are scaled (kScale)
// or skipped (kSkip); kAhead would read query frames not given yet. Each cell is the float
// SequenceDistancesInPlace gives for the same D (the same operations in double).
class SequenceRowSums {
 public:
  // Throws std::logic_error when L < 1 or `partial` is kAhead.
  explicit SequenceRowSums(int sequence_length, SequencePartial partial = SequencePartial::kScale);
  // The next row pushed is the first of a new query traversal.
  void Restart();
  // Row Rows() of the query traversal: `d` holds D(q, j) for the columns 0 .. columns - 1 and
  // receives S(q, j). `col_starts`: the first column of each column traversal, increasing from
  // 0 (empty: one). From one row to the next the columns may stay or grow by one (a frame
  // that becomes a candidate), and the starts may only gain new ones at the end; else
  // std::logic_error (Restart first). Memory: L + 1 rows of floats and two of doubles.
  void Push(float* d, int columns, const std::vector<int>& col_starts);
  int Rows() const { return rows_; }  // rows pushed since the last Restart

 private:
  int length_;
  SequencePartial partial_;
  int rows_ = 0, columns_ = 0;
  std::vector<int> starts_, first_;
  std::vector<std::vector<float>> ring_;  // row r of D in slot r % (L + 1)
  std::vector<double> prev_, cur_;
};

// kAhead after a sweep that left every cell with fewer than L terms +inf (kSkip): each such
// cell takes the value of the cell AheadShift steps forward along its diagonal (a cell with L
// terms, never changed here), or stays +inf. `row_starts`/`col_starts` and `reverse` as for
// SequenceDistancesInPlace. Used by it, and by a run spread over processes on the gathered
// matrix (normalised cells are copied as they are).
void FillAheadCells(cv::Mat1f& s, int sequence_length, const std::vector<int>& row_starts,
                    const std::vector<int>& col_starts, bool reverse);

// D: N x M single-frame distances (rows: frames i, columns: frames j), replaced by S.
// `row_starts` and `col_starts` are the first frame of each traversal along the rows and the
// columns, in increasing order and starting with 0 (empty means {0}: one traversal).
// `threads` = 0 uses all cores. Throws std::logic_error when L < 1 or the starts are not
// increasing from 0. kBoth needs a second N x M matrix for the time of the call.
void SequenceDistancesInPlace(cv::Mat1f& d, int sequence_length,
                              const std::vector<int>& row_starts = {},
                              const std::vector<int>& col_starts = {},
                              SequenceDirection direction = SequenceDirection::kForward,
                              int threads = 0, SequencePartial partial = SequencePartial::kAhead);

// The same, returning S in a new matrix and leaving D as it is.
cv::Mat1f SequenceDistances(const cv::Mat1f& d, int sequence_length,
                            const std::vector<int>& row_starts = {},
                            const std::vector<int>& col_starts = {},
                            SequenceDirection direction = SequenceDirection::kForward,
                            int threads = 0, SequencePartial partial = SequencePartial::kAhead);

}  // namespace openable
