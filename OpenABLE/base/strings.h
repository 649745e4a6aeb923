// Small text helpers shared by every module: case folding, trimming, number formatting.
#pragma once

#include <string>
#include <string_view>

namespace openable {

// ASCII lower- and upper-case copies (names of options, descriptors and file extensions are
// compared case-insensitively; locale-independent on purpose).
std::string Lower(std::string_view s);
std::string Upper(std::string_view s);

// `s` without leading and trailing spaces, tabs, CR and LF.
std::string Trim(std::string_view s);

// A number as users read it in messages and in Config.txt: the shortest of printf's %g with
// six significant digits ("0.47", "2500", "1e+06"), "inf" for infinity.
std::string FormatNumber(double value);

}  // namespace openable
