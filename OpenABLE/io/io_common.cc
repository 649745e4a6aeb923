#include "OpenABLE/io/io_common.h"

#include <cctype>
#include <filesystem>
#include <stdexcept>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"

namespace openable::io_internal {

std::string FirstLine(const std::string& text) {
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find_first_of("\r\n", begin);
    if (end == std::string::npos) end = text.size();
    std::string line;
    for (std::size_t k = begin; k < end; ++k) {
      const auto u = static_cast<unsigned char>(text[k]);
      line += (u < 0x20 || u == 0x7f) ? ' ' : text[k];
    }
    const std::size_t first = line.find_first_not_of(' ');
    if (first != std::string::npos) {
      const std::size_t last = line.find_last_not_of(' ');
      return line.substr(first, last - first + 1);
    }
    begin = end + 1;
  }
  return "unknown error";
}

std::string NormalizeExtension(const std::string& extension) {
  std::string e = Lower(extension);
  if (!e.empty() && e.front() == '.') e.erase(0, 1);
  return e;
}

std::string ExtensionOf(const std::string& file_name) {
  return NormalizeExtension(std::filesystem::path(file_name).extension().string());
}

int ResolveRangeEnd(int first, int last, int count, const std::string& what_plural,
                    const std::string& what_singular, const std::string& where) {
  const int end = last == -1 ? count : last;
  if (first < 0 || end > count || first >= end) {
    throw InputError("Initial_image/Final_image: range [" + std::to_string(first) + ", " +
                     (last == -1 ? std::string("end") : std::to_string(last)) +
                     ") is empty or outside the " + std::to_string(count) + " " +
                     (count == 1 ? what_singular : what_plural) + " of " + where);
  }
  return end;
}

void CheckIndex(int i, int size, const char* where) {
  if (i < 0 || i >= size) {
    throw std::logic_error(std::string(where) + ": frame index " + std::to_string(i) +
                           " outside [0, " + std::to_string(size) + ")");
  }
}

}  // namespace openable::io_internal
