// openable_map: maps of places that persist and grow, one session (traversal) at a time, on
// the command line: add a traversal's frames, describe a map, merge two, query one with
// another traversal's frames. A thin layer over OpenABLE/online/map_program.h.
#include <iostream>
#include <string>

#include "OpenABLE/OpenABLE.h"
#include "OpenABLE/base/interrupt.h"
#include "OpenABLE/base/program.h"
#include "OpenABLE/online/map_program.h"

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << openable::kMapUsage;
      return 0;
    }
    if (arg == "--version") {
      std::cout << "openable_map (OpenABLE " << openable::kVersion << ")\n";
      return 0;
    }
  }
  // Signals remove the temporary of a map being written, and say whether the map changed.
  openable::InstallInterruptCleanup("openable_map");
  openable::MapCommandLine command_line;
  const std::string usage_error = openable::ParseMapCommandLine(argc, argv, command_line);
  if (!usage_error.empty()) {
    std::cerr << "openable_map: " << usage_error << " (see openable_map --help)\n";
    return openable::kExitUsageError;
  }
  return openable::RunProgram("openable_map",
                              [&] { return openable::RunMapCommand(command_line); });
}
