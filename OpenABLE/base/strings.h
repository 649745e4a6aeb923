// Small text helpers shared by every module: case folding, trimming, number formatting.
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

// The formatter of numbers in the text outputs (messages, reports, CSV and JSON files): printf's
// %g with `significant` digits. With the default six, a number as users read it in messages and
// in Config.txt ("0.47", "2500", "1e+06"); nine in the CSV and JSON figures, seventeen where a
// value must read back exactly. "inf", "-inf" and "nan" as printf writes them.
std::string FormatNumber(double value, int significant = 6);

// `value` with `decimals` digits after the point (printf's "%.3f" for 3): figures in tables and
// reports.
std::string FormatFixed(double value, int decimals);

// For a message about a path that was not found: " (relative to the working directory
// "/home/user/run")" when `path` is relative, else "". A relative path in a Config.txt is
// relative to where the program runs, not to the file, which is what users most often miss.
std::string WorkingDirectoryNote(std::string_view path);

}  // namespace openable
