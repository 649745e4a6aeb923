// Small text helpers shared by every module: case folding, trimming, number formatting, text
// made valid UTF-8 for the outputs.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace openable {

// ASCII lower- and upper-case copies (names of options, descriptors and file extensions are
// compared case-insensitively; locale-independent on purpose).
std::string Lower(std::string_view s);
std::string Upper(std::string_view s);

// `s` without leading and trailing spaces, tabs, CR and LF.
std::string Trim(std::string_view s);

// The pieces of `s` between `separator`s, each trimmed (an empty piece stays: "a,,b" gives
// "a", "", "b"; "" gives one empty piece).
std::vector<std::string> SplitTrimmed(std::string_view s, char separator);

// `parts` with `separator` between them ("HOG+LDB"; "" for none).
std::string JoinStrings(const std::vector<std::string>& parts, std::string_view separator);

// The formatter of numbers in the text outputs (messages, reports, CSV and JSON files): printf's
// %g with `significant` digits. With the default six, a number as users read it in messages and
// in Config.txt ("0.47", "2500", "1e+06"); nine in the CSV and JSON figures, seventeen where a
// value must read back exactly. "inf", "-inf" and "nan" as printf writes them.
std::string FormatNumber(double value, int significant = 6);

// `value` with `decimals` digits after the point (printf's "%.3f" for 3): figures in tables and
// reports.
std::string FormatFixed(double value, int decimals);

// "WxH" (640x480) of a size in messages and saved maps; also rows x cols of a matrix.
std::string SizeText(int width, int height);
// The same of anything with `width` and `height` (cv::Size).
template <typename Size>
std::string SizeText(const Size& size) {
  return SizeText(size.width, size.height);
}

// `s` as text that every output can show: `s` itself, byte for byte, when it is valid UTF-8;
// otherwise each byte that is not part of a well-formed UTF-8 sequence (The Unicode Standard,
// section 3.9, Table 3-7: no overlong forms, no surrogates D800-DFFF, nothing above U+10FFFF, no
// truncated sequence, no lone continuation byte) written as the four characters \xNN (two
// lower-case hex digits), the well-formed sequences around it kept. File names on Linux are
// bytes, so a name in another encoding ("caf\xe9.png", Latin-1) would otherwise reach files that
// declare UTF-8. The one rule of every text output: the HTML report, the JSON documents, the
// CSV files and the terminal (Quoted() and the programs' report, note and error lines); files
// are still opened by their real names.
//
// Escapes rather than U+FFFD keep names that differ only in their invalid bytes distinct and
// give the user the bytes to type (docs/output_formats.md, "Names that are not UTF-8").
// nlohmann-json cannot write them, so the JSON writer applies this function before nlohmann
// escapes the string.
std::string ToValidUtf8(std::string_view s);

// For a message about a path that was not found: " (relative to the working directory
// "/home/user/run")" when `path` is relative, else "". A relative path in a Config.txt is
// relative to where the program runs, not to the file, which is what users most often miss.
std::string WorkingDirectoryNote(std::string_view path);

}  // namespace openable
