#include "matching/search/binary_ivf.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "OpenABLE/base/threading.h"
#include "matching/distances.h"
#include "matching/search/ivf_cells.h"

namespace openable {
namespace {

constexpr int kRounds = 8;            // k-majority rounds
constexpr int kSamplePerCell = 32;    // sample rows per cell
constexpr int kMinSample = 65536;     // sample rows at least (all rows when fewer)
constexpr int kRowsPerTask = 1024;    // rows assigned per task
const char kMagic[8] = {'O', 'A', 'B', 'I', 'V', 'F', '1', '\0'};

// The index of the first smallest of n >= 1 distances (non-negative whole numbers as floats).
// Their bits order them as integers, and the smallest of integers is a loop the compiler
// vectorises where std::min_element over floats stays scalar (it took as long as the Hamming
// kernel that computed the distances).
int FirstSmallest(const float* d, int n) {
  std::int32_t smallest = std::numeric_limits<std::int32_t>::max();
  for (int i = 0; i < n; ++i) {
    std::int32_t bits = 0;
    std::memcpy(&bits, &d[i], sizeof bits);
    smallest = bits < smallest ? bits : smallest;
  }
  for (int i = 0; i < n; ++i) {
    std::int32_t bits = 0;
    std::memcpy(&bits, &d[i], sizeof bits);
    if (bits == smallest) return i;
  }
  return 0;
}

// The nearest centre of each row of `rows` (ties: the lower centre), on `threads` threads.
std::vector<int> NearestCentres(const HammingReferences& centres, const cv::Mat& rows,
                                int threads) {
  std::vector<int> out(static_cast<std::size_t>(rows.rows));
  const int cells = centres.Size();
  const int tasks = (rows.rows + kRowsPerTask - 1) / kRowsPerTask;
  ParallelFor(tasks, threads, [&](int t) {
    std::vector<float> d(static_cast<std::size_t>(cells));
    const int r1 = std::min(rows.rows, (t + 1) * kRowsPerTask);
    for (int r = t * kRowsPerTask; r < r1; ++r) {
      centres.Distances(rows.ptr<std::uint8_t>(r), d.data());
      out[static_cast<std::size_t>(r)] = FirstSmallest(d.data(), cells);
    }
  });
  return out;
}

// k-majority: `cells` centres trained on a sample of `references` (see binary_ivf.h).
cv::Mat TrainCentres(const cv::Mat& references, int cells, std::uint64_t seed, int threads) {
  const int n = references.rows, width = references.cols;
  std::mt19937_64 rng(seed);
  const int sample_rows =
      std::min(n, std::max(kMinSample, static_cast<int>(std::min<std::int64_t>(
                                           n, std::int64_t{kSamplePerCell} * cells))));
  cv::Mat sample(sample_rows, width, CV_8U);
  if (sample_rows == n) {
    references.copyTo(sample);
  } else {
    // Drawn with replacement: a repeated row weighs twice, which does not matter here.
    for (int i = 0; i < sample_rows; ++i)
      references.row(static_cast<int>(rng() % static_cast<std::uint64_t>(n)))
          .copyTo(sample.row(i));
  }
  // First centres: `cells` sample rows in an order drawn with the seed.
  std::vector<int> pick(static_cast<std::size_t>(sample_rows));
  for (int i = 0; i < sample_rows; ++i) pick[static_cast<std::size_t>(i)] = i;
  for (int i = 0; i < cells; ++i) {
    const int j = i + static_cast<int>(rng() % static_cast<std::uint64_t>(sample_rows - i));
    std::swap(pick[static_cast<std::size_t>(i)], pick[static_cast<std::size_t>(j)]);
  }
  cv::Mat centres(cells, width, CV_8U);
  for (int c = 0; c < cells; ++c)
    sample.row(pick[static_cast<std::size_t>(c)]).copyTo(centres.row(c));
  const int bits = 8 * width;
  std::vector<std::int32_t> ones(static_cast<std::size_t>(cells) * bits);
  std::vector<std::int32_t> members(static_cast<std::size_t>(cells));
  for (int round = 0; round < kRounds; ++round) {
    const std::vector<int> cell = NearestCentres(HammingReferences(centres), sample, threads);
    std::fill(ones.begin(), ones.end(), 0);
    std::fill(members.begin(), members.end(), 0);
    for (int r = 0; r < sample_rows; ++r) {
      const int c = cell[static_cast<std::size_t>(r)];
      ++members[static_cast<std::size_t>(c)];
      std::int32_t* count = &ones[static_cast<std::size_t>(c) * bits];
      const std::uint8_t* row = sample.ptr<std::uint8_t>(r);
      for (int b = 0; b < width; ++b)
        for (int k = 0; k < 8; ++k) count[8 * b + k] += (row[b] >> k) & 1;
    }
    // Each bit of a centre: set when most of its rows have it (a tie clears it). A cell
    // without rows keeps its centre.
    for (int c = 0; c < cells; ++c) {
      const std::int32_t m = members[static_cast<std::size_t>(c)];
      if (m == 0) continue;
      const std::int32_t* count = &ones[static_cast<std::size_t>(c) * bits];
      std::uint8_t* centre = centres.ptr<std::uint8_t>(c);
      for (int b = 0; b < width; ++b) {
        std::uint8_t byte = 0;
        for (int k = 0; k < 8; ++k)
          byte = static_cast<std::uint8_t>(byte | ((2 * count[8 * b + k] > m ? 1 : 0) << k));
        centre[b] = byte;
      }
    }
  }
  return centres;
}

void Put32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

std::uint32_t Get32(const std::uint8_t* p) {
  return std::uint32_t{p[0]} | (std::uint32_t{p[1]} << 8) | (std::uint32_t{p[2]} << 16) |
         (std::uint32_t{p[3]} << 24);
}

class BinaryIvfIndex final : public EngineIndex {
 public:
  BinaryIvfIndex(const cv::Mat& references, const ApproximateOptions& options,
                 const std::vector<std::uint8_t>& saved) {
    if (references.depth() != CV_8U)
      throw std::invalid_argument("binary_ivf: expected binary rows (CV_8U), got " +
                                  cv::typeToString(references.type()));
    const int n = references.rows;
    std::vector<int> cell;
    if (saved.empty()) {
      centres_ = TrainCentres(references, IvfCellCount(options.ivf_lists, n), options.seed,
                              options.threads);
      cell = NearestCentres(HammingReferences(centres_), references, options.threads);
    } else {
      Read(saved, references, cell);
    }
    std::vector<std::vector<int>> ids(static_cast<std::size_t>(centres_.rows));
    for (int r = 0; r < n; ++r)
      ids[static_cast<std::size_t>(cell[static_cast<std::size_t>(r)])].push_back(r);
    rows_ = n;
    cells_ = MakeIvfCells(references, centres_, ids);
  }

  CandidateLists Search(const cv::Mat& queries, const ApproximateOptions& options) const override {
    return SearchIvfCells(*cells_, queries, std::min(options.k, rows_), options.nprobe,
                          options.threads);
  }

  // Magic, cells, row bytes, rows (u32 each, little-endian), the centres, each row's cell.
  std::vector<std::uint8_t> Serialize() const override {
    std::vector<std::uint8_t> out(kMagic, kMagic + sizeof kMagic);
    Put32(out, static_cast<std::uint32_t>(centres_.rows));
    Put32(out, static_cast<std::uint32_t>(centres_.cols));
    Put32(out, static_cast<std::uint32_t>(rows_));
    out.insert(out.end(), centres_.data, centres_.data + centres_.total());
    std::vector<std::uint32_t> cell(static_cast<std::size_t>(rows_));
    for (std::size_t c = 0; c < cells_->ids.size(); ++c)
      for (const int r : cells_->ids[c])
        cell[static_cast<std::size_t>(r)] = static_cast<std::uint32_t>(c);
    for (const std::uint32_t c : cell) Put32(out, c);
    return out;
  }

 private:
  void Read(const std::vector<std::uint8_t>& saved, const cv::Mat& references,
            std::vector<int>& cell) {
    const auto fail = [](const std::string& why) {
      throw std::invalid_argument("binary_ivf: the saved index " + why);
    };
    if (saved.size() < sizeof kMagic + 12 ||
        std::memcmp(saved.data(), kMagic, sizeof kMagic) != 0)
      fail("is not a binary_ivf index");
    const std::uint8_t* p = saved.data() + sizeof kMagic;
    const std::uint32_t cells = Get32(p), width = Get32(p + 4), rows = Get32(p + 8);
    if (width != static_cast<std::uint32_t>(references.cols) ||
        rows != static_cast<std::uint32_t>(references.rows) || cells == 0 || cells > rows)
      fail("has " + std::to_string(cells) + " cells over " + std::to_string(rows) +
           " rows of " + std::to_string(width) + " bytes; expected its " +
           std::to_string(references.rows) + " references of " +
           std::to_string(references.cols) + " bytes");
    const std::size_t expected = sizeof kMagic + 12 + std::size_t{cells} * width +
                                 std::size_t{rows} * 4;
    if (saved.size() != expected)
      fail("holds " + std::to_string(saved.size()) + " bytes, expected " +
           std::to_string(expected));
    p += 12;
    centres_ = cv::Mat(static_cast<int>(cells), static_cast<int>(width), CV_8U);
    std::memcpy(centres_.data, p, std::size_t{cells} * width);
    p += std::size_t{cells} * width;
    cell.resize(rows);
    for (std::uint32_t r = 0; r < rows; ++r, p += 4) {
      const std::uint32_t c = Get32(p);
      if (c >= cells)
        fail("puts row " + std::to_string(r) + " in cell " + std::to_string(c) + " of " +
             std::to_string(cells));
      cell[r] = static_cast<int>(c);
    }
  }

  cv::Mat centres_;
  int rows_ = 0;
  std::unique_ptr<IvfCells> cells_;
};

std::unique_ptr<EngineIndex> Build(const cv::Mat& references, const ApproximateOptions& options,
                                   const std::vector<std::uint8_t>& saved) {
  return std::make_unique<BinaryIvfIndex>(references, options, saved);
}

// The rows again, packed by cell for the kernels, and a 4-byte row number each (the centres
// are few); ApproximateIndex keeps no copy of its own (owns_rows).
std::int64_t BytesPerRow(const ApproximateOptions& /*options*/, int /*depth*/,
                         std::int64_t row_bytes) {
  return row_bytes + 4;
}

}  // namespace

const ApproximateEngineEntry kBinaryIvfEngine = {
    "binary_ivf",  // name
    "inverted files of binary rows trained by k-majority and scanned by OpenABLE's Hamming "
    "kernels (no FAISS)",  // summary
    /*needs_faiss=*/false,
    /*binary_only=*/true,
    /*owns_rows=*/true,  // packed by cell
    &Build,
    &BytesPerRow,
};

}  // namespace openable
