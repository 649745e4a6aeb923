// The commands of openable_map (examples/openable_map.cc, docs/library.md, "openable_map"):
// add a traversal's frames to a map as a session, describe a map, merge two, query one with
// another traversal's frames, over OnlineDetector's saved maps (online.h).
#pragma once

#include <string>
#include <vector>

namespace openable {

// The command line of openable_map.
struct MapCommandLine {
  std::string command;                  // add, tune, info, merge, query
  std::vector<std::string> positional;  // the map(s)
  std::string images, config, time, output, threshold, frames;
  std::string descriptors;  // --descriptors: rows computed elsewhere (.npy)
  std::vector<std::string> sessions, sets;
  bool json = false, quiet = false;
};

// What --help prints.
extern const char* const kMapUsage;

// Parses argv (after the program's name). Returns "" or one line naming the bad argument.
std::string ParseMapCommandLine(int argc, const char* const* argv, MapCommandLine& out);

// Runs the command; its report goes to stdout, progress to stderr. Throws InputError as the
// library does (the map is then unchanged). Returns the exit status.
int RunMapCommand(const MapCommandLine& command_line);

}  // namespace openable
