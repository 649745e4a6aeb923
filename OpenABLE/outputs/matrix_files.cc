#include "OpenABLE/outputs/matrix_files.h"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include <opencv2/core/utility.hpp>

#include "OpenABLE/base/error.h"
#include "OpenABLE/io/npy.h"

namespace openable {
namespace {

// The text of a float as printf's "%.6g" writes it (std::to_chars with a precision: no locale,
// no format string), remembered by its bits: a matrix of Hamming sums divided by their largest
// holds a few thousand distinct values (at most L x bits + 1), so most cells are a lookup.
// Direct-mapped, one per thread; a collision formats again. The digits are those of to_chars
// either way.
class FloatTexts {
 public:
  FloatTexts() : entries_(kSize) {}
  std::string_view Of(float v) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    Entry& e = entries_[(bits * 2654435761u) >> (32 - kBits)];
    if (e.length == 0 || e.bits != bits) {
      const std::to_chars_result r =
          std::to_chars(e.text, e.text + sizeof e.text, v, std::chars_format::general, 6);
      e.bits = bits;
      e.length = static_cast<std::uint8_t>(r.ptr - e.text);
    }
    return {e.text, e.length};
  }

 private:
  static constexpr int kBits = 14;
  static constexpr std::size_t kSize = std::size_t{1} << kBits;
  struct Entry {
    std::uint32_t bits = 0;
    std::uint8_t length = 0;  // 0: empty
    char text[19];            // "-1.23457e-05" and the like: at most 13 characters
  };
  std::vector<Entry> entries_;
};

// Rows [r0, r1) of `m` as text into `out` (appended).
void FormatRows(const cv::Mat& m, int r0, int r1, FloatTexts& texts, std::string& out) {
  char buf[8];
  for (int i = r0; i < r1; ++i) {
    for (int j = 0; j < m.cols; ++j) {
      if (j) out.push_back(' ');
      if (m.depth() == CV_8U) {
        const std::to_chars_result res =
            std::to_chars(buf, buf + sizeof buf, int{m.at<std::uint8_t>(i, j)});
        out.append(buf, res.ptr);
      } else {
        out.append(texts.Of(m.at<float>(i, j)));
      }
    }
    out.push_back('\n');
  }
}

}  // namespace

TextChunks::TextChunks(const cv::Mat& m) : m_(m) {
  if (m.depth() != CV_8U && m.depth() != CV_32F)
    throw std::logic_error("TextChunks: expected CV_8U or CV_32F");
}

bool TextChunks::Next(std::string_view& piece) {
  if (next_row_ >= m_.rows) return false;
  // A chunk is kBlocks blocks of kBlockRows rows, formatted in parallel (one block per task)
  // and written while the next is formatted: the whole text is never in memory.
  constexpr int kBlockRows = 32, kBlocks = 16;
  const int r0 = next_row_, r1 = std::min(m_.rows, r0 + kBlockRows * kBlocks);
  const int blocks = (r1 - r0 + kBlockRows - 1) / kBlockRows;
  parts_.resize(static_cast<std::size_t>(blocks));
  cv::parallel_for_(cv::Range(0, blocks), [&](const cv::Range& range) {
    thread_local FloatTexts texts;
    for (int b = range.start; b < range.end; ++b) {
      std::string& out = parts_[static_cast<std::size_t>(b)];
      out.clear();
      FormatRows(m_, r0 + b * kBlockRows, std::min(r1, r0 + (b + 1) * kBlockRows), texts, out);
    }
  });
  chunk_.clear();
  for (const std::string& part : parts_) chunk_ += part;
  next_row_ = r1;
  piece = chunk_;
  return true;
}

std::string EncodeText(const cv::Mat& m) {
  TextChunks chunks(m);
  std::string out;
  for (std::string_view piece; chunks.Next(piece);) out += piece;
  return out;
}

std::string EncodeMatches(const std::vector<Match>& matches, bool csv) {
  if (csv) {
    std::string out = "query,reference,distance,rank,score\n";
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
      *p++ = '\n';
      out.append(buf, p);
    }
    return out;
  }
  // A structured .npy: one record of 20 bytes per match.
  std::string out = NpyHeaderOf(
      "[('query', '<i4'), ('reference', '<i4'), ('distance', '<f4'), ('rank', '<i4'), "
      "('score', '<f4')]",
      "(" + std::to_string(matches.size()) + ",)");
  out.reserve(out.size() + matches.size() * 20);
  for (const Match& k : matches) {
    char rec[20];
    std::memcpy(rec, &k.query, 4);
    std::memcpy(rec + 4, &k.reference, 4);
    std::memcpy(rec + 8, &k.distance, 4);
    std::memcpy(rec + 12, &k.rank, 4);
    std::memcpy(rec + 16, &k.score, 4);
    out.append(rec, 20);
  }
  return out;
}

}  // namespace openable
