// The command line shared by the programs that read Config.txt (Test_OpenABLE,
// openable_snaps, openable_sweep): [Config.txt] [--set Key=Value ...] [--quiet] [--json]
// [--print-config] [--help] [--help-keys [GROUP]] [--help-markdown] [--version].
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/base/progress.h"
#include "config/config.h"

namespace openable {

struct CommandLine {
  std::string config_path;             // empty: defaults, then the overrides
  std::vector<std::string> overrides;  // "Key=Value" from --set, in order
  bool quiet = false;                  // --quiet, -q
  bool json = false;                   // --json: the final report as one JSON object on stdout
  bool print_config = false;           // --print-config
  bool help = false;                   // -h, --help
  bool help_keys = false;              // --help-keys [GROUP]
  std::string help_group;              // its GROUP, or empty: every key
  bool help_markdown = false;          // --help-markdown
  bool version = false;                // --version
  // The program's own options that take a value ("--vary", "--output"), as given, in order.
  std::vector<std::pair<std::string, std::string>> options;
};

// What a program adds to the shared command line.
struct ProgramOptions {
  // Its own options that take a value ("--vary" for "--vary X" or "--vary=X"), collected into
  // CommandLine::options in the order given.
  std::vector<std::string> value_options;
  // Flags that stand for a Config.txt key: {"--radius", "Ground_truth_radius"} makes
  // "--radius 10" the override "Ground_truth_radius=10", in order among the --set.
  std::vector<std::pair<std::string, std::string>> key_flags;
  // A configuration (a file or an override) is required.
  bool needs_configuration = true;
};

// What --help prints: one screen. `usage` (the synopsis, what the program does, its options),
// then the keys people change most, each with its default and a short meaning, then `example`,
// then where every other key is (--help-keys, docs/configuration.md).
struct ProgramHelp {
  std::string usage;
  std::vector<std::pair<std::string, std::string>> keys;  // {key, short meaning}
  std::string example;
};
std::string FormatProgramHelp(const std::string& program, const ProgramHelp& help);

// Parses argv. Returns an empty string on success, or one line (prefixed with `program`)
// naming the bad argument and pointing at --help: an unknown option, an option without its
// value, two configuration files, or (when `options` needs one) neither a file nor an
// override. --help and --version are answered whatever follows: the parsing stops there.
std::string ParseCommandLine(int argc, const char* const* argv, const std::string& program,
                             CommandLine& out, const ProgramOptions& options);
// The same with the program's own value options alone.
std::string ParseCommandLine(int argc, const char* const* argv, const std::string& program,
                             CommandLine& out, const std::vector<std::string>& value_options = {});

// Prints every key (or those of `group`, ConfigHelpText) on stdout and returns 0, or prints
// the one-line error for an unknown group on stderr and returns 2 (a usage error).
int AnswerHelpKeys(const std::string& program, const std::string& group);

// Answers what needs no run: --help (FormatProgramHelp), --help-keys (every key, or one
// group's; an unknown group is a usage error naming the groups), --help-markdown (the key
// reference), --version (`version_line`), or a usage error (on stderr). Returns the exit status
// (0, or 2 for a usage error), or -1 when the program should go on and run.
int AnswerWithoutRunning(const CommandLine& command_line, const std::string& usage_error,
                         const std::string& program, const ProgramHelp& help,
                         const std::string& version_line);

// The configuration a command line asks for: the file (or the defaults) with the overrides
// applied in order. Throws InputError as LoadConfig and ApplyOverride do.
Config ConfigOf(const CommandLine& command_line);

// The main of a program that reads Config.txt, around its work: keeps only OpenCV's errors in
// its log (OpenCV's video back ends print warnings of their own that the library reports as one
// InputError line), installs the cleanup of interrupted runs (interrupt.h), parses the command
// line, answers --help, --help-keys, --help-markdown, --version and usage errors
// (AnswerWithoutRunning),
// reads the configuration (ConfigOf), prints it for --print-config, and otherwise returns the
// status of `body`, given the configuration, the command line and the progress reporter of the
// run (stderr, off with --quiet); errors become exit statuses through RunProgram
// (OpenABLE/base/program.h). `program` must outlive the process (a string literal).
// `value_options` as ParseCommandLine. Started by mpirun with several processes, a program
// whose `spreads_over_processes` is true connects them (OpenABLE/cluster/cluster.h) and process 0
// alone prints; any other program refuses in one line.
int RunConfigProgram(
    int argc, const char* const* argv, const char* program, const ProgramHelp& help,
    const std::string& version_line,
    const std::function<int(const Config&, const CommandLine&, ProgressReporter&)>& body,
    const std::vector<std::string>& value_options = {}, bool spreads_over_processes = false);

}  // namespace openable
