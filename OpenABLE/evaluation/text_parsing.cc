#include "OpenABLE/evaluation/text_parsing.h"

#include <cctype>
#include <charconv>
#include <cmath>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/input_file.h"
#include "OpenABLE/base/strings.h"

namespace openable::evaluation_internal {

void RequireFile(const std::string& path, const std::string& where) { CheckInputFile(path, where); }

std::string ReadWholeFile(const std::string& path, const std::string& where) {
  return ReadInputFile(path, where);
}

bool ParseNumber(std::string_view token, double* value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto r = std::from_chars(token.data(), end, *value);
  return r.ec == std::errc() && r.ptr == end;
}

bool ParseIndex(std::string_view field, std::int64_t* value) {
  std::string_view f = field;
  if (!f.empty() && f.front() == '+') f.remove_prefix(1);
  const char* end = f.data() + f.size();
  const auto r = std::from_chars(f.data(), end, *value);
  if (!f.empty() && r.ec == std::errc() && r.ptr == end) {
    return *value >= -kMaxIndex && *value <= kMaxIndex;
  }
  double d = 0.0;
  if (!ParseNumber(field, &d) || !std::isfinite(d) || d != std::floor(d) ||
      std::abs(d) > static_cast<double>(kMaxIndex)) {
    return false;
  }
  *value = static_cast<std::int64_t>(d);
  return true;
}

bool IsHeaderLine(const Line& line) {
  const auto digit = [](char c) { return c >= '0' && c <= '9'; };
  for (const std::string_view f : line.fields) {
    std::size_t i = 0;
    if (i < f.size() && (f[i] == '+' || f[i] == '-')) ++i;
    if (i < f.size() && f[i] == '.') ++i;
    if (i < f.size() && digit(f[i])) return false;
    double value = 0;  // "nan", "inf": numbers too
    if (ParseNumber(f, &value)) return false;
  }
  return !line.fields.empty();
}

void SplitFields(std::string_view s, std::vector<std::string_view>* out) {
  out->clear();
  std::size_t i = 0;
  bool after_comma = false;
  while (true) {
    while (i < s.size() && IsBlank(s[i])) ++i;
    if (i == s.size()) break;
    if (s[i] == ',') {
      if (out->empty() || after_comma) out->emplace_back();
      after_comma = true;
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < s.size() && !IsBlank(s[j]) && s[j] != ',') ++j;
    out->push_back(s.substr(i, j - i));
    after_comma = false;
    i = j;
  }
}

}  // namespace openable::evaluation_internal
