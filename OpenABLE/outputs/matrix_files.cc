#include "OpenABLE/outputs/matrix_files.h"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <opencv2/core/utility.hpp>
#include <stdexcept>

#include "OpenABLE/base/error.h"
#include "OpenABLE/io/npy.h"

namespace openable {
namespace {

// The texts of the cells, each followed by a space, in slots of kSlot bytes: a cell is written
// by copying a whole slot (a fixed-size copy, no loop over its characters) and moving on by its
// length, so the buffer written into keeps kSlot bytes of room past a row's last cell.
constexpr std::size_t kSlot = 16;

// The text of a float as printf's "%.6g" writes it (std::to_chars with a precision: no locale,
// no format string), remembered by its bits: a matrix of Hamming sums divided by their largest
// holds a few thousand distinct values (at most L x bits + 1), so most cells are a lookup.
// Direct-mapped, one per thread; a collision formats again. The digits are those of to_chars
// either way.
class FloatTexts {
 public:
  struct Entry {
    std::uint32_t bits = 0;
    std::uint32_t length = 0;  // with the space; 0: empty
    char text[kSlot];          // "-1.23457e-05 " and the like: at most 13 characters
  };
  FloatTexts() : entries_(kSize) {}
  const Entry& Of(float v) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    Entry& e = entries_[(bits * 2654435761u) >> (32 - kBits)];
    if (e.length == 0 || e.bits != bits) {
      const std::to_chars_result r =
          std::to_chars(e.text, e.text + sizeof e.text - 1, v, std::chars_format::general, 6);
      *r.ptr = ' ';
      e.bits = bits;
      e.length = static_cast<std::uint32_t>(r.ptr + 1 - e.text);
    }
    return e;
  }

 private:
  static constexpr int kBits = 14;
  static constexpr std::size_t kSize = std::size_t{1} << kBits;
  std::vector<Entry> entries_;
};

// The texts of 0-255 with their space, for thresholded (CV_8U) matrices.
struct ByteTexts {
  ByteTexts() {
    for (int v = 0; v < 256; ++v) {
      char* end = std::to_chars(text[v], text[v] + kSlot - 1, v).ptr;
      *end = ' ';
      length[v] = static_cast<std::uint8_t>(end + 1 - text[v]);
    }
  }
  char text[256][kSlot];
  std::uint8_t length[256];
};

// Rows [r0, r1) of `m` as text into `out` from its start (grown when needed, never shrunk: it
// is reused for the next rows); returns the length of the text.
std::size_t FormatRows(const cv::Mat& m, int r0, int r1, FloatTexts& texts, std::string& out) {
  static const ByteTexts bytes;
  std::size_t used = 0;
  const std::size_t row_room = static_cast<std::size_t>(m.cols) * kSlot + 1;
  for (int i = r0; i < r1; ++i) {
    if (out.size() < used + row_room) out.resize(std::max(used + row_room, 2 * out.size()));
    char* p = &out[used];
    if (m.depth() == CV_8U) {
      const std::uint8_t* row = m.ptr<std::uint8_t>(i);
      for (int j = 0; j < m.cols; ++j) {
        std::memcpy(p, bytes.text[row[j]], kSlot);
        p += bytes.length[row[j]];
      }
    } else {
      const float* row = m.ptr<float>(i);
      for (int j = 0; j < m.cols; ++j) {
        const FloatTexts::Entry& e = texts.Of(row[j]);
        std::memcpy(p, e.text, kSlot);
        p += e.length;
      }
    }
    if (m.cols > 0) --p;  // the last cell's space
    *p++ = '\n';
    used = static_cast<std::size_t>(p - out.data());
  }
  return used;
}

}  // namespace

TextChunks::TextChunks(const cv::Mat& m) : m_(m) {
  if (m.depth() != CV_8U && m.depth() != CV_32F)
    throw std::logic_error("TextChunks: expected CV_8U or CV_32F");
}

bool TextChunks::Next(std::string_view& piece) {
  if (next_block_ == blocks_) {
    if (next_row_ >= m_.rows) return false;
    // kBlocks blocks of kBlockRows rows at a time, formatted in parallel (one block per task),
    // then handed out one block per call: the whole text is never in memory.
    const int r0 = next_row_, r1 = std::min(m_.rows, r0 + kBlockRows * kBlocks);
    blocks_ = (r1 - r0 + kBlockRows - 1) / kBlockRows;
    next_block_ = 0;
    cv::parallel_for_(cv::Range(0, blocks_), [&](const cv::Range& range) {
      thread_local FloatTexts texts;
      for (int b = range.start; b < range.end; ++b) {
        const std::size_t k = static_cast<std::size_t>(b);
        lengths_[k] = FormatRows(m_, r0 + b * kBlockRows, std::min(r1, r0 + (b + 1) * kBlockRows),
                                 texts, parts_[k]);
      }
    });
    next_row_ = r1;
  }
  const std::size_t k = static_cast<std::size_t>(next_block_++);
  piece = std::string_view(parts_[k].data(), lengths_[k]);
  return true;
}

std::string EncodeText(const cv::Mat& m) {
  TextChunks chunks(m);
  std::string out;
  for (std::string_view piece; chunks.Next(piece);) out += piece;
  return out;
}

MatchVerdicts VerdictsOf(const std::vector<Match>& matches, double threshold,
                         const AgreementOptions* consistency, bool accept_none) {
  MatchVerdicts v;
  if (accept_none || threshold < 0) return v;
  int queries = 0;
  for (const Match& m : matches)
    if (m.rank == 1) queries = std::max(queries, m.query + 1);
  v.accepted = AcceptedMatches(matches, queries, threshold, nullptr);
  v.confirmed = consistency != nullptr ? AcceptedMatches(matches, queries, threshold, consistency)
                                       : v.accepted;
  return v;
}

std::string EncodeMatches(const std::vector<Match>& matches, bool csv,
                          const MatchVerdicts& verdicts) {
  // The verdicts of a match: those of its query's best match for rank 1, else none.
  const auto verdict = [&](const Match& k, const std::vector<std::uint8_t>& flags) {
    return k.rank == 1 && k.query >= 0 && static_cast<std::size_t>(k.query) < flags.size() &&
                   flags[static_cast<std::size_t>(k.query)] != 0
               ? 1
               : 0;
  };
  if (csv) {
    std::string out = "query,reference,distance,rank,score,accepted,confirmed\n";
    char buf[128];
    for (const Match& k : matches) {
      char* p = buf;
      p = std::to_chars(p, buf + sizeof buf, k.query).ptr;
      *p++ = ',';
      p = std::to_chars(p, buf + sizeof buf, k.reference).ptr;
      *p++ = ',';
      p = std::to_chars(p, buf + sizeof buf, k.distance, std::chars_format::general, 7).ptr;
      *p++ = ',';
      p = std::to_chars(p, buf + sizeof buf, k.rank).ptr;
      *p++ = ',';
      p = std::to_chars(p, buf + sizeof buf, k.score, std::chars_format::general, 7).ptr;
      *p++ = ',';
      *p++ = verdict(k, verdicts.accepted) ? '1' : '0';
      *p++ = ',';
      *p++ = verdict(k, verdicts.confirmed) ? '1' : '0';
      *p++ = '\n';
      out.append(buf, p);
    }
    return out;
  }
  // A structured .npy: one record of 22 bytes per match, the first 20 as files without the
  // verdicts had them.
  constexpr std::size_t kRecord = 22;
  std::string out = NpyHeaderOf(
      "[('query', '<i4'), ('reference', '<i4'), ('distance', '<f4'), ('rank', '<i4'), "
      "('score', '<f4'), ('accepted', '|u1'), ('confirmed', '|u1')]",
      "(" + std::to_string(matches.size()) + ",)");
  out.reserve(out.size() + matches.size() * kRecord);
  for (const Match& k : matches) {
    char rec[kRecord];
    std::memcpy(rec, &k.query, 4);
    std::memcpy(rec + 4, &k.reference, 4);
    std::memcpy(rec + 8, &k.distance, 4);
    std::memcpy(rec + 12, &k.rank, 4);
    std::memcpy(rec + 16, &k.score, 4);
    rec[20] = static_cast<char>(verdict(k, verdicts.accepted));
    rec[21] = static_cast<char>(verdict(k, verdicts.confirmed));
    out.append(rec, kRecord);
  }
  return out;
}

}  // namespace openable
