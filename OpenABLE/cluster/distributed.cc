#include "OpenABLE/cluster/distributed.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <tuple>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "matching/distances.h"
#include "matching/large_matrix.h"
#include "matching/matrix.h"

namespace openable {
namespace {

// Frames [first, last) of a source, numbered from 0: one process's share.
class FrameRange : public FrameSource {
 public:
  FrameRange(const FrameSource& source, int first, int last)
      : source_(source), first_(first), last_(last) {}
  int Size() const override { return last_ - first_; }
  std::string FrameName(int i) const override { return source_.FrameName(first_ + i); }
  cv::Mat Read(int i) const override { return source_.Read(first_ + i); }
  bool ParallelReads() const override { return source_.ParallelReads(); }

 private:
  const FrameSource& source_;
  int first_, last_;
};

// A share as bytes: its rows, width, type and count, the kept frames (indices of the whole
// source), the frame size (0 x 0 when every frame was skipped), the first frame's name, and
// the skipped frames' messages.
struct ShareHeader {
  std::int64_t rows = 0, kept = 0, skipped = 0, first_name = 0;
  std::int32_t width = 0, type = 0, frame_w = 0, frame_h = 0;
};

void AppendString(std::vector<char>& out, const std::string& s) {
  const std::int64_t n = static_cast<std::int64_t>(s.size());
  AppendBytes(out, &n, 1);
  AppendBytes(out, s.data(), s.size());
}

std::string ReadString(const char*& p) {
  std::int64_t n = 0;
  std::memcpy(&n, p, sizeof n);
  p += sizeof n;
  std::string s(p, static_cast<std::size_t>(n));
  p += n;
  return s;
}

}  // namespace

DescribedSequence DescribeShared(Cluster& cluster, const FrameSource& source,
                                 const FrameDescriber& describer, const DescribeOptions& options,
                                 const std::function<void(int, int)>& progress) {
  if (!cluster.Distributed()) return DescribeSequence(source, describer, options, progress);
  // Plain variables, not a structured binding: C++17 lambdas cannot capture bindings.
  const std::pair<int, int> share_rows = cluster.Share(source.Size());
  const int first = share_rows.first, last = share_rows.second;
  DescribedSequence mine;
  cluster.Agree([&] {
    if (last > first) {
      const FrameRange range(source, first, last);
      DescribeOptions share = options;
      share.share = true;
      share.share_first = first;
      mine = DescribeSequence(range, describer, share, progress);
      for (int& k : mine.kept) k += first;
    }
  });
  std::vector<char> bytes;
  ShareHeader h;
  const cv::Mat rows = mine.rows.isContinuous() ? mine.rows : mine.rows.clone();
  h.rows = rows.rows;
  h.kept = static_cast<std::int64_t>(mine.kept.size());
  h.skipped = static_cast<std::int64_t>(mine.skipped.size());
  h.width = describer.RowWidth();
  h.type = describer.RowType();
  h.frame_w = mine.frame_size.width;
  h.frame_h = mine.frame_size.height;
  AppendBytes(bytes, &h, 1);
  AppendBytes(bytes, rows.data, rows.total() * rows.elemSize());
  AppendBytes(bytes, mine.kept.data(), mine.kept.size());
  AppendString(bytes, mine.kept.empty() ? std::string() : source.FrameName(mine.kept.front()));
  for (const std::string& s : mine.skipped) AppendString(bytes, s);

  std::vector<std::int64_t> sizes;
  const std::vector<char> all = cluster.AllGather(bytes, &sizes);
  DescribedSequence out;
  std::vector<cv::Mat> blocks;
  std::string size_frame;
  const char* p = all.data();
  for (int r = 0; r < cluster.Size(); ++r) {
    ShareHeader s;
    std::memcpy(&s, p, sizeof s);
    p += sizeof s;
    cv::Mat block(static_cast<int>(s.rows), s.width, s.type);
    const std::size_t row_bytes = block.total() * block.elemSize();
    if (row_bytes > 0) std::memcpy(block.data, p, row_bytes);
    p += row_bytes;
    if (s.rows > 0) blocks.push_back(block);
    const std::vector<int> kept =
        FromBytes<int>(p, s.kept * static_cast<std::int64_t>(sizeof(int)));
    p += s.kept * static_cast<std::int64_t>(sizeof(int));
    out.kept.insert(out.kept.end(), kept.begin(), kept.end());
    const std::string first_name = ReadString(p);
    for (std::int64_t k = 0; k < s.skipped; ++k) out.skipped.push_back(ReadString(p));
    const cv::Size frame(s.frame_w, s.frame_h);
    if (frame.area() == 0) continue;
    // One size for every frame of a sequence, as DescribeSequence checks within a share.
    if (out.frame_size.area() == 0) {
      out.frame_size = frame;
      size_frame = first_name;
    } else if (frame != out.frame_size) {
      throw InputError(std::string(options.key.empty() ? "" : options.key + ": ") + "image \"" +
                       first_name + "\" is " + SizeText(frame) + " but \"" + size_frame + "\" is " +
                       SizeText(out.frame_size) +
                       " (expected the frames of one sequence to have one size)");
    }
  }
  if (out.kept.empty())
    throw InputError(std::string(options.key.empty() ? "" : options.key + ": ") + "none of the " +
                     std::to_string(source.Size()) + " frames could be read (first failure: " +
                     (out.skipped.empty() ? std::string("none") : out.skipped.front()) + ")");
  if (blocks.size() == 1)
    out.rows = blocks.front();
  else
    cv::vconcat(blocks, out.rows);
  return out;
}

cv::Mat1f DistanceRows(const cv::Mat& rows, int row_first, int row_last, Metric metric, int strips,
                       PanoramaMatching mode, int threads, const PairProgress& progress) {
  if (row_first == 0 && row_last == rows.rows)
    return PairwiseDistances(rows, metric, strips, mode, threads, progress);
  if (row_last <= row_first) return cv::Mat1f(0, rows.rows);  // a process with no rows
  // L2 cells of a symmetric matrix come from its lower triangle's products (L2Distances): the
  // rows of a share are computed from the same products, never as rows against references.
  if (metric == Metric::kL2 && (strips == 1 || mode == PanoramaMatching::kAligned))
    return L2DistanceRows(rows, row_first, row_last, threads, progress);
  return PanoramaDistances(rows.rowRange(row_first, row_last), rows, strips, mode, threads,
                           progress, metric);
}

DenseShare DenseShareOf(const Cluster& cluster, int n, int sequence_length) {
  // Shares and their first computed row on multiples of the tiles of the L2 matrices
  // (kL2Tile): every row is then computed in a tile of the same rows as in a single process
  // (the sub-panoramas' matrices are computed as rows against references), and its L2 cells
  // are the same floats; no tile is computed by two processes.
  constexpr int kRowBlock = kL2Tile;
  const auto aligned = [&](int row) {
    return row >= n ? n : std::min(n, (row + kRowBlock / 2) / kRowBlock * kRowBlock);
  };
  DenseShare s;
  const auto [first, last] = cluster.Share(n);
  s.first = aligned(first);
  s.last = aligned(last);
  s.history = std::max(0, s.first - (sequence_length - 1)) / kRowBlock * kRowBlock;
  return s;
}

std::vector<int> ShareRowStarts(const std::vector<int>& starts, const DenseShare& share) {
  std::vector<int> out = {0};
  for (const int s : starts)
    if (s > share.history && s < share.last) out.push_back(s - share.history);
  return out;
}

cv::Mat1f GatherRows(Cluster& cluster, const cv::Mat1f& mine, int n, int cols) {
  if (!cluster.Distributed()) return mine;
  // Straight into process 0's matrix: it holds the matrix once, as a single process does.
  const cv::Mat1f rows = mine.isContinuous() ? mine : mine.clone();
  cv::Mat1f out;
  if (cluster.Rank() == 0) out = LargeMatrix(n, cols);
  const std::int64_t bytes = static_cast<std::int64_t>(rows.total()) * sizeof(float);
  const std::int64_t capacity =
      cluster.Rank() == 0 ? static_cast<std::int64_t>(n) * cols * sizeof(float) : 0;
  if (cluster.Rank() == 0 && !out.isContinuous())
    throw std::logic_error("GatherRows: the matrix is not one block");
  cluster.GatherInto(reinterpret_cast<const char*>(rows.data), bytes,
                     cluster.Rank() == 0 ? reinterpret_cast<char*>(out.data) : nullptr, capacity);
  return out;
}

std::vector<Match> SharedBoundedMatches(Cluster& cluster, const MatchBlock& block,
                                        const KeepRules& rules, BoundedOptions options,
                                        const MatchShare& match_share, float& max_distance) {
  if (cluster.Distributed()) {
    std::tie(options.query_begin, options.query_end) = cluster.Share(block.query_count);
    options.normalize = false;
  }
  std::vector<Match> mine;
  float largest = 0.0f;
  cluster.Agree([&] { mine = match_share(options, largest); });
  if (!cluster.Distributed()) {
    max_distance = largest;
    return mine;
  }
  // Every share's largest is a float; their maximum is one of them, exact through double.
  max_distance = static_cast<float>(cluster.Max(largest));
  NormalizeMatches(mine, max_distance, rules.score);
  std::vector<char> bytes;
  AppendBytes(bytes, mine.data(), mine.size());
  std::vector<std::int64_t> sizes;
  const std::vector<char> all = cluster.GatherToFirst(bytes, &sizes);
  if (cluster.Rank() != 0) return {};
  return FromBytes<Match>(all.data(), static_cast<std::int64_t>(all.size()));
}

}  // namespace openable
