#include "OpenABLE/evaluation/text_parsing.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <system_error>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"

namespace openable::evaluation_internal {

namespace fs = std::filesystem;

void RequireFile(const std::string& path, const std::string& where) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) throw InputError(where + ": file not found" + WorkingDirectoryNote(path));
  if (fs::is_directory(st)) throw InputError(where + ": is a folder; expected a file");
}

std::string ReadWholeFile(const std::string& path, const std::string& where) {
  RequireFile(path, where);
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(where + ": cannot be opened for reading");
  std::string data((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (f.bad()) throw InputError(where + ": read error");
  return data;
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
