#include "OpenABLE/evaluation/text_parsing.h"

#include <cctype>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <system_error>

#include "OpenABLE/base/error.h"

namespace openable::evaluation_internal {

namespace fs = std::filesystem;

void RequireFile(const std::string& path, const std::string& where) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) throw InputError(where + ": file not found");
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


}  // namespace openable::evaluation_internal
