// The steps of a run spread over processes (cluster.h) that differ from a single process's:
// each computes its share and the shares are put together so that the result is the one a
// single process gives (docs/distributed.md). With one process each step is the plain one.
#pragma once

#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "OpenABLE/cluster/cluster.h"
#include "OpenABLE/describe/describe.h"
#include "OpenABLE/io/frame_source.h"
#include "descriptors/frame_describer.h"
#include "matching/bounded.h"
#include "matching/panorama.h"
#include "matching/sequence.h"

namespace openable {

// Every process describes its share of the frames of `source` (contiguous, in rank order) and
// the rows, kept frames, skipped frames and frame size are gathered on every process: the
// DescribeSequence of the whole source. `progress` counts this process's frames. A failure on
// any process (an unreadable frame) is thrown on every process (Cluster::Agree).
DescribedSequence DescribeShared(Cluster& cluster, const FrameSource& source,
                                 const FrameDescriber& describer, const DescribeOptions& options,
                                 const std::function<void(int, int)>& progress);

// The single-frame distance matrix, what PairwiseDistances gives, for rows
// [row_first, row_last) only: those rows against every row.
cv::Mat1f DistanceRows(const cv::Mat& rows, int row_first, int row_last, Metric metric, int strips,
                       PanoramaMatching mode, int threads, const PairProgress& progress);

// The rows of this process in a dense run of `n` frames: [first, last), and the rows of the
// single-frame matrix it computes, [history, last), history = first - (L - 1) (the sequences
// of its first rows read L - 1 rows back), not before the start of the run.
struct DenseShare {
  int first = 0, last = 0, history = 0;
};
DenseShare DenseShareOf(const Cluster& cluster, int n, int sequence_length);

// The traversal starts, as SequenceDistancesInPlace takes them, of the rows [history, last) of
// a matrix whose traversals start at `starts`: 0 and every start inside the rows.
std::vector<int> ShareRowStarts(const std::vector<int>& starts, const DenseShare& share);

// Process 0 receives the rows of every process's normalised share (rank order: the whole
// matrix, `n` rows); the other processes get an empty matrix.
cv::Mat1f GatherRows(Cluster& cluster, const cv::Mat1f& mine, int n, int cols);

// The bounded matches of the whole block: every process matches its share of the queries
// (`match_share` called with BoundedOptions whose query_begin/end and normalize say which
// queries and whether to normalise, returning the matches and their largest distance) with raw
// distances, the largest distance of all shares normalises them (Eq. 5), and process 0 receives
// every match (in query order, as one process keeps them); the others get none.
// `max_distance` is the largest of all.
using MatchShare = std::function<std::vector<Match>(const BoundedOptions&, float& largest)>;
std::vector<Match> SharedBoundedMatches(Cluster& cluster, const MatchBlock& block,
                                        const KeepRules& rules, BoundedOptions options,
                                        const MatchShare& match_share, float& max_distance);

}  // namespace openable
