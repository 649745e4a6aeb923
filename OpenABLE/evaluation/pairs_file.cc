#include "OpenABLE/evaluation/pairs_file.h"

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/text_parsing.h"

namespace openable {

using evaluation_internal::ForEachLine;
using evaluation_internal::Line;
using evaluation_internal::ParseIndex;
using evaluation_internal::ReadWholeFile;

PairsFile ReadPairsFile(const std::string& path, int base, const std::string& what) {
  PairsFile out;
  out.where = what + " " + Quoted(path);
  const std::string data = ReadWholeFile(path, out.where);

  if (base == -1) {
    bool says_1 = false, says_0 = false;
    ForEachLine(data, [&](const Line& line) {
      const std::string c = Lower(line.comment);
      says_1 = says_1 || c.find("1-based") != std::string::npos;
      says_0 = says_0 || c.find("0-based") != std::string::npos;
    });
    if (says_1 && says_0)
      throw InputError(out.where +
                       ": comments say both \"0-based\" and \"1-based\"; set "
                       "Ground_truth_base to 0 or 1");
    base = says_1 ? 1 : 0;
    out.base_note = says_1 || says_0 ? " (" + std::to_string(base) + "-based, as a comment says)"
                                     : " (0-based; set Ground_truth_base to 1 if the file "
                                       "counts from 1)";
  } else {
    out.base_note = " (" + std::to_string(base) + "-based, Ground_truth_base)";
  }
  out.base = base;

  bool first_content = true;
  ForEachLine(data, [&](const Line& line) {
    if (line.fields.empty()) return;
    const std::string at = out.where + ":" + std::to_string(line.number);
    const bool header = first_content && evaluation_internal::IsHeaderLine(line);
    first_content = false;
    if (header) {
      out.header_line = line.number;
      for (const std::string_view f : line.fields)
        out.header += (out.header.empty() ? "" : ",") + std::string(f);
      return;
    }
    if (line.fields.size() < 2)
      throw InputError(at + ": line has 1 value, " + Quoted(line.fields[0]) +
                       "; expected two frame indices \"a,b\" separated by a comma or blanks");
    std::int64_t raw[2];
    for (int k = 0; k < 2; ++k) {
      if (!ParseIndex(line.fields[static_cast<std::size_t>(k)], &raw[k]))
        throw InputError(at + ": value " + Quoted(line.fields[static_cast<std::size_t>(k)]) +
                         " in column " + std::to_string(k + 1) +
                         " is not an integer of at most 10^15 in size; expected two frame "
                         "indices \"a,b\"");
    }
    out.pairs.push_back({raw[0] - base, raw[1] - base, line.number});
  });
  if (out.pairs.empty())
    throw InputError(out.where +
                     ": holds no pair; expected one pair of frame indices \"a,b\" "
                     "per line (an empty ground truth would give figures of 0)");
  return out;
}

}  // namespace openable
