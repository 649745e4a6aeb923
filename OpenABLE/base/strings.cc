#include "OpenABLE/base/strings.h"

#include <cstdio>
#include <filesystem>

#include "OpenABLE/base/error.h"

namespace openable {

std::string Lower(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return out;
}

std::string Upper(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
  return out;
}

std::string Trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return std::string(s.substr(b, e - b + 1));
}

std::string JoinStrings(const std::vector<std::string>& parts, std::string_view separator) {
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (i > 0) out += separator;
    out += parts[i];
  }
  return out;
}

std::vector<std::string> SplitTrimmed(std::string_view s, char separator) {
  std::vector<std::string> pieces;
  for (std::size_t start = 0;;) {
    const std::size_t end = s.find(separator, start);
    pieces.push_back(Trim(s.substr(start, end == std::string_view::npos ? end : end - start)));
    if (end == std::string_view::npos) return pieces;
    start = end + 1;
  }
}

std::string SizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

std::string FormatNumber(double value, int significant) {
  char buffer[64];  // %.17g of any double takes at most 24 characters
  std::snprintf(buffer, sizeof buffer, "%.*g", significant, value);
  return buffer;
}

std::string FormatFixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

namespace {

// The length of the well-formed UTF-8 sequence that starts `s` (The Unicode Standard, Table
// 3-7), 0 when none does. The second byte's range depends on the first (E0: A0-BF, no overlong
// 3-byte form; ED: 80-9F, no surrogate; F0: 90-BF, no overlong 4-byte form; F4: 80-8F, nothing
// above U+10FFFF); every other following byte is 80-BF. C0, C1 and F5-FF start nothing.
// Written here: none of the libraries the project links checks UTF-8 and tells where it fails
// (nlohmann-json's decoder is private to its serializer and only refuses, drops or replaces;
// OpenCV has none; OpenImageIO's utf8_to_unicode lets invalid sequences through), and ICU would
// be a new dependency of every program for these few lines.
std::size_t WellFormedLength(std::string_view s) {
  const auto byte = [s](std::size_t i) { return static_cast<unsigned char>(s[i]); };
  const unsigned char first = byte(0);
  if (first < 0x80) return 1;
  std::size_t length = 0;
  unsigned char low = 0x80, high = 0xbf;  // the second byte's range
  if (first >= 0xc2 && first <= 0xdf) {
    length = 2;
  } else if (first == 0xe0) {
    length = 3, low = 0xa0;
  } else if ((first >= 0xe1 && first <= 0xec) || first == 0xee || first == 0xef) {
    length = 3;
  } else if (first == 0xed) {
    length = 3, high = 0x9f;
  } else if (first == 0xf0) {
    length = 4, low = 0x90;
  } else if (first >= 0xf1 && first <= 0xf3) {
    length = 4;
  } else if (first == 0xf4) {
    length = 4, high = 0x8f;
  } else {
    return 0;
  }
  if (s.size() < length || byte(1) < low || byte(1) > high) return 0;
  for (std::size_t i = 2; i < length; ++i)
    if (byte(i) < 0x80 || byte(i) > 0xbf) return 0;
  return length;
}

}  // namespace

std::string ToValidUtf8(std::string_view s) {
  static const char* const kHex = "0123456789abcdef";
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const std::size_t length = WellFormedLength(s.substr(i));
    if (length > 0) {
      out.append(s.substr(i, length));
      i += length;
      continue;
    }
    // Only this byte: the next one may start a well-formed sequence of its own.
    const auto u = static_cast<unsigned char>(s[i++]);
    out += "\\x";
    out += kHex[u >> 4];
    out += kHex[u & 0xf];
  }
  return out;
}

std::string WorkingDirectoryNote(std::string_view path) {
  const std::filesystem::path p(path);
  if (path.empty() || p.is_absolute()) return "";
  std::error_code ec;
  const std::filesystem::path cwd = std::filesystem::current_path(ec);
  if (ec) return " (a relative path)";
  return " (relative to the working directory " + Quoted(cwd.string()) + ")";
}

}  // namespace openable
