// The one reader of loop-pair files, shared by every program and by Python: the evaluation's
// ground truth (Ground_truth_type pairs, openable_evaluate --gt-type pairs, openable.evaluate),
// and openable_snaps' loops (Snaps_loops pairs). One format, one set of checks.
//
// Format: one pair of frame numbers per line, separated by a comma or blanks ("12,7", "12 7",
// "12, 7"); further columns are ignored; '#' starts a comment. A first line whose first field
// is not a number is a header and is skipped. Frame numbers count from 0, or from 1 when
// `base` is 1 (or, with base -1, when a comment says "1-based").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace openable {

struct PairsFile {
  struct Pair {
    // The two frame numbers, 0-based (the base subtracted): negative for a number below the
    // base, which the caller refuses with the range it expects.
    std::int64_t a = 0, b = 0;
    int line = 0;  // line of the file, from 1
  };
  std::vector<Pair> pairs;  // in file order
  int base = 0;             // the base the file was read with
  // How the base was chosen, for messages: " (1-based, as a comment says)", " (0-based,
  // Ground_truth_base)", " (0-based; set Ground_truth_base to 1 if the file counts from 1)".
  std::string base_note;
  std::string where;  // `what` and the path, as messages name the file
  // The first line, when it was read as a header and skipped (text_parsing.h's rule), and its
  // number; 0 and "" when the file has none. Reports say so: no line is dropped unsaid.
  int header_line = 0;
  std::string header;
};

// Reads `path`. `base`: 0 or 1, or -1 to read it from a comment ("0-based" or "1-based"; both
// is an error), else 0. `what` names the file in messages ("ground truth pairs", "loop pairs
// file"). Throws InputError "<what> "<path>":<line>: ..." on a missing or unreadable file, a
// line with one value, a value that is not an integer (or larger than 10^15 in size), and a
// file that holds no pair.
PairsFile ReadPairsFile(const std::string& path, int base, const std::string& what);

}  // namespace openable
