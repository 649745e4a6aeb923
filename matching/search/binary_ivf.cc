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

constexpr int kRounds = 8;          // k-majority rounds
constexpr int kSamplePerCell = 32;  // sample rows per cell
constexpr int kMinSample = 65536;   // sample rows at least (all rows when fewer)
constexpr int kRowsPerTask = 1024;  // rows assigned per task
const char kMagic[8] = {'O', 'A', 'B', 'I', 'V', 'F', '1', '\0'};   // first saved form
const char kMagic2[8] = {'O', 'A', 'B', 'I', 'V', 'F', '2', '\0'};  // the form written now

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
      references.row(static_cast<int>(rng() % static_cast<std::uint64_t>(n))).copyTo(sample.row(i));
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

std::size_t Padded8(std::size_t bytes) { return (bytes + 7) / 8 * 8; }

bool LittleEndianHost() {
  const std::uint32_t one = 1;
  std::uint8_t first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

[[noreturn]] void Fail(const std::string& why) {
  throw std::invalid_argument("binary_ivf: the saved index " + why);
}

// The saved form (Serialize), 8-byte aligned sections so that it can be searched where it
// lies (a memory-mapped map file):
//   magic "OABIVF2\0"; u32 cells, row bytes, rows, 0
//   the centres, cells x row bytes, zero-padded to a multiple of 8
//   u32 offsets of the cells' rows, cells + 1 of them (0 .. rows), padded to 8
//   i32 the rows of each cell in cell order, rows of them, padded to 8
//   each non-empty cell's rows as HammingReferences packs them (64-bit words)
// Integers and words little-endian, as x86-64 and arm64 hold them in memory: a big-endian host
// refuses the form (the map's rows then get their cells again: OnlineDetector::LoadMap).
// The first version ("OABIVF1\0": cells, row bytes, rows, the centres, each row's cell as u32)
// is still read; its cells are packed again from the references.
struct Layout {
  std::uint32_t cells = 0, width = 0, rows = 0;
  std::size_t centres = 0, offsets = 0, ids = 0, packed = 0;  // byte offsets of the sections
  Layout(std::uint32_t k, std::uint32_t w, std::uint32_t n) : cells(k), width(w), rows(n) {
    centres = 24;
    offsets = centres + Padded8(std::size_t{k} * w);
    ids = offsets + Padded8((std::size_t{k} + 1) * 4);
    packed = ids + Padded8(std::size_t{n} * 4);
  }
};

class BinaryIvfIndex final : public EngineIndex {
 public:
  BinaryIvfIndex(const cv::Mat& references, const ApproximateOptions& options,
                 const SavedIndex& saved) {
    if (references.depth() != CV_8U)
      throw std::invalid_argument("binary_ivf: expected binary rows (CV_8U), got " +
                                  cv::typeToString(references.type()));
    const int n = references.rows;
    rows_ = n;
    if (!saved.empty() && saved.size >= sizeof kMagic &&
        std::memcmp(saved.data, kMagic2, sizeof kMagic2) == 0) {
      ReadInPlace(saved, references);
      return;
    }
    std::vector<int> cell;
    if (saved.empty()) {
      centres_ = TrainCentres(references, IvfCellCount(options.ivf_lists, n), options.seed,
                              options.threads);
      cell = NearestCentres(HammingReferences(centres_), references, options.threads);
    } else {
      ReadFirstVersion(saved, references, cell);
    }
    std::vector<std::vector<int>> ids(static_cast<std::size_t>(centres_.rows));
    for (int r = 0; r < n; ++r)
      ids[static_cast<std::size_t>(cell[static_cast<std::size_t>(r)])].push_back(r);
    cells_ = MakeIvfCells(references, centres_, ids);
  }

  CandidateLists Search(const cv::Mat& queries, const ApproximateOptions& options) const override {
    return SearchIvfCells(*cells_, queries, std::min(options.k, rows_), options.nprobe,
                          options.threads);
  }

  std::vector<std::uint8_t> Serialize() const override {
    const Layout at(static_cast<std::uint32_t>(centres_.rows),
                    static_cast<std::uint32_t>(centres_.cols), static_cast<std::uint32_t>(rows_));
    std::vector<std::uint8_t> out(kMagic2, kMagic2 + sizeof kMagic2);
    Put32(out, at.cells);
    Put32(out, at.width);
    Put32(out, at.rows);
    Put32(out, 0);
    out.insert(out.end(), centres_.data, centres_.data + centres_.total());
    out.resize(at.offsets, 0);
    for (const std::uint32_t o : cells_->offsets) Put32(out, o);
    out.resize(at.ids, 0);
    for (std::uint32_t i = 0; i < at.rows; ++i)
      Put32(out, static_cast<std::uint32_t>(cells_->ids[i]));
    out.resize(at.packed, 0);
    for (int c = 0; c < cells_->Cells(); ++c) {
      if (cells_->Count(c) == 0) continue;
      const std::size_t words = HammingReferences::PackedWords(cells_->Count(c), centres_.cols);
      const std::uint64_t* w = cells_->rows[static_cast<std::size_t>(c)]->PackedData();
      for (std::size_t i = 0; i < words; ++i)
        for (int k = 0; k < 8; ++k) out.push_back(static_cast<std::uint8_t>(w[i] >> (8 * k)));
    }
    return out;
  }

 private:
  // The second version: structure checked (every row in exactly one cell, sizes exact), then
  // searched where it lies when the bytes are kept by saved.owner, aligned and in this host's
  // order; otherwise from a copy of them.
  void ReadInPlace(const SavedIndex& saved, const cv::Mat& references) {
    if (saved.size < 24) Fail("is truncated (" + std::to_string(saved.size) + " bytes)");
    const std::uint8_t* p = saved.data + sizeof kMagic2;
    const Layout at(Get32(p), Get32(p + 4), Get32(p + 8));
    if (at.width != static_cast<std::uint32_t>(references.cols) ||
        at.rows != static_cast<std::uint32_t>(references.rows) || at.cells == 0 ||
        at.cells > at.rows)
      Fail("has " + std::to_string(at.cells) + " cells over " + std::to_string(at.rows) +
           " rows of " + std::to_string(at.width) + " bytes; expected its " +
           std::to_string(references.rows) + " references of " + std::to_string(references.cols) +
           " bytes");
    // The offsets first: the packed section's size follows from them.
    if (saved.size < at.packed)
      Fail("holds " + std::to_string(saved.size) + " bytes, fewer than its cells' " +
           std::to_string(at.packed));
    std::vector<std::uint32_t> offsets(std::size_t{at.cells} + 1);
    std::size_t words = 0;
    for (std::size_t c = 0; c <= at.cells; ++c) {
      offsets[c] = Get32(saved.data + at.offsets + 4 * c);
      if ((c == 0 && offsets[c] != 0) || (c > 0 && offsets[c] < offsets[c - 1]) ||
          offsets[c] > at.rows)
        Fail("has cell offsets out of order at cell " + std::to_string(c));
      if (c > 0)
        words += HammingReferences::PackedWords(static_cast<int>(offsets[c] - offsets[c - 1]),
                                                static_cast<int>(at.width));
    }
    if (offsets.back() != at.rows)
      Fail("holds " + std::to_string(offsets.back()) + " rows in its cells, expected " +
           std::to_string(at.rows));
    const std::size_t expected = at.packed + 8 * words;
    if (saved.size != expected)
      Fail("holds " + std::to_string(saved.size) + " bytes, expected " + std::to_string(expected));
    if (!LittleEndianHost()) Fail("holds little-endian words; this host is big-endian");
    // Read in place, or from an aligned copy when the bytes are not kept or not aligned.
    const std::uint8_t* base = saved.data;
    std::shared_ptr<const void> owner = saved.owner;
    if (!owner || reinterpret_cast<std::uintptr_t>(base) % 8 != 0) {
      auto copy = std::make_shared<std::vector<std::uint64_t>>((saved.size + 7) / 8, 0);
      std::memcpy(copy->data(), saved.data, saved.size);
      base = reinterpret_cast<const std::uint8_t*>(copy->data());
      owner = copy;
    }
    centres_ = cv::Mat(static_cast<int>(at.cells), static_cast<int>(at.width), CV_8U);
    std::memcpy(centres_.data, base + at.centres, centres_.total());
    auto cells = std::make_unique<IvfCells>();
    cells->centres = std::make_unique<HammingReferences>(centres_);
    cells->offsets = std::move(offsets);
    cells->ids = reinterpret_cast<const std::int32_t*>(base + at.ids);
    cells->owner = owner;
    // Every row in exactly one cell: the ids index the references and the caller's rows.
    std::vector<std::uint8_t> seen(at.rows, 0);
    for (std::uint32_t i = 0; i < at.rows; ++i) {
      const std::int32_t id = cells->ids[i];
      if (id < 0 || static_cast<std::uint32_t>(id) >= at.rows || seen[id])
        Fail("names row " + std::to_string(id) +
             (id < 0 || static_cast<std::uint32_t>(id) >= at.rows ? " of " + std::to_string(at.rows)
                                                                  : " twice"));
      seen[id] = 1;
    }
    const std::uint64_t* packed = reinterpret_cast<const std::uint64_t*>(base + at.packed);
    cells->rows.resize(at.cells);
    for (int c = 0; c < static_cast<int>(at.cells); ++c) {
      const int count = cells->Count(c);
      if (count == 0) continue;
      cells->rows[static_cast<std::size_t>(c)] =
          std::make_unique<HammingReferences>(packed, count, static_cast<int>(at.width));
      packed += HammingReferences::PackedWords(count, static_cast<int>(at.width));
    }
    cells_ = std::move(cells);
  }

  void ReadFirstVersion(const SavedIndex& saved, const cv::Mat& references,
                        std::vector<int>& cell) {
    if (saved.size < sizeof kMagic + 12 || std::memcmp(saved.data, kMagic, sizeof kMagic) != 0)
      Fail("is not a binary_ivf index");
    const std::uint8_t* p = saved.data + sizeof kMagic;
    const std::uint32_t cells = Get32(p), width = Get32(p + 4), rows = Get32(p + 8);
    if (width != static_cast<std::uint32_t>(references.cols) ||
        rows != static_cast<std::uint32_t>(references.rows) || cells == 0 || cells > rows)
      Fail("has " + std::to_string(cells) + " cells over " + std::to_string(rows) + " rows of " +
           std::to_string(width) + " bytes; expected its " + std::to_string(references.rows) +
           " references of " + std::to_string(references.cols) + " bytes");
    const std::size_t expected =
        sizeof kMagic + 12 + std::size_t{cells} * width + std::size_t{rows} * 4;
    if (saved.size != expected)
      Fail("holds " + std::to_string(saved.size) + " bytes, expected " + std::to_string(expected));
    p += 12;
    centres_ = cv::Mat(static_cast<int>(cells), static_cast<int>(width), CV_8U);
    std::memcpy(centres_.data, p, std::size_t{cells} * width);
    p += std::size_t{cells} * width;
    cell.resize(rows);
    for (std::uint32_t r = 0; r < rows; ++r, p += 4) {
      const std::uint32_t c = Get32(p);
      if (c >= cells)
        Fail("puts row " + std::to_string(r) + " in cell " + std::to_string(c) + " of " +
             std::to_string(cells));
      cell[r] = static_cast<int>(c);
    }
  }

  cv::Mat centres_;
  int rows_ = 0;
  std::unique_ptr<IvfCells> cells_;
};

std::unique_ptr<EngineIndex> Build(const cv::Mat& references, const ApproximateOptions& options,
                                   const SavedIndex& saved) {
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
