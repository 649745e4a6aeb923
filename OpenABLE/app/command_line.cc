#include "OpenABLE/app/command_line.h"

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <opencv2/core/utils/logger.hpp>
#include <sstream>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/interrupt.h"
#include "OpenABLE/base/program.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/cluster/cluster.h"

namespace openable {

std::string ParseCommandLine(int argc, const char* const* argv, const std::string& program,
                             CommandLine& out, const std::vector<std::string>& value_options) {
  ProgramOptions options;
  options.value_options = value_options;
  return ParseCommandLine(argc, argv, program, out, options);
}

std::string ParseCommandLine(int argc, const char* const* argv, const std::string& program,
                             CommandLine& out, const ProgramOptions& options) {
  out = CommandLine();
  // "--name value" or "--name=value": the value, or false when `a` is not `name`.
  std::string value;
  int i = 1;
  bool missing = false;
  const auto takes = [&](const std::string& a, const std::string& name) {
    if (a.rfind(name + "=", 0) == 0) {
      value = a.substr(name.size() + 1);
      return true;
    }
    if (a != name) return false;
    missing = i + 1 >= argc;
    if (!missing) value = argv[++i];
    return true;
  };
  for (; i < argc; ++i) {
    const std::string a = argv[i];
    const auto own = std::find_if(options.value_options.begin(), options.value_options.end(),
                                  [&](const std::string& o) { return takes(a, o); });
    const auto flag = own != options.value_options.end()
                          ? options.key_flags.end()
                          : std::find_if(options.key_flags.begin(), options.key_flags.end(),
                                         [&](const auto& f) { return takes(a, f.first); });
    if (missing) return program + ": " + a + " needs a value (see --help)";
    if (own != options.value_options.end()) {
      out.options.emplace_back(*own, value);
    } else if (flag != options.key_flags.end()) {
      out.overrides.push_back(flag->second + "=" + value);
    } else if (a == "-h" || a == "--help") {
      out.help = true;
      return "";
    } else if (a == "--help-keys" || a.rfind("--help-keys=", 0) == 0) {
      out.help_keys = true;
      if (a.size() > 11)
        out.help_group = a.substr(12);
      else if (i + 1 < argc && argv[i + 1][0] != '-')
        out.help_group = argv[i + 1];
      return "";
    } else if (a == "--help-markdown") {
      out.help_markdown = true;
      return "";
    } else if (a == "--version") {
      out.version = true;
      return "";
    } else if (a == "--set") {
      if (i + 1 >= argc) return program + ": --set needs Key=Value (see --help)";
      out.overrides.push_back(argv[++i]);
    } else if (a.rfind("--set=", 0) == 0) {
      out.overrides.push_back(a.substr(6));
    } else if (a == "--quiet" || a == "-q") {
      out.quiet = true;
    } else if (a == "--json") {
      out.json = true;
    } else if (a == "--print-config") {
      out.print_config = true;
    } else if (!a.empty() && a[0] == '-') {
      return program + ": unknown option \"" + a + "\" (see --help)";
    } else if (out.config_path.empty()) {
      out.config_path = a;
    } else {
      return program + ": more than one configuration file (\"" + out.config_path + "\" and \"" +
             a + "\"); expected one (see --help)";
    }
  }
  if (options.needs_configuration && out.config_path.empty() && out.overrides.empty())
    return program + ": no configuration given; expected " + program +
           " Config.txt or --set Key=Value (see --help)";
  return "";
}

std::string FormatProgramHelp(const std::string& program, const ProgramHelp& help) {
  std::string text = help.usage;
  if (!help.keys.empty()) {
    text +=
        "Keys people change most (in Config.txt as 'Key: value', or --set Key=Value;\n"
        "default in brackets):\n";
    size_t width = 0;
    for (const auto& k : help.keys) width = std::max(width, k.first.size());
    Config defaults;
    for (const auto& [key, meaning] : help.keys) {
      const std::string value = ConfigValueText(defaults, key);
      text +=
          "  " + key + std::string(width + 2 - key.size(), ' ') + meaning + " [" + value + "]\n";
    }
    text += "\n";
  }
  text += help.example;
  // The groups by their first words, which --help-keys takes ("Description").
  std::string groups;
  for (const std::string& g : ConfigGroupNames())
    groups += (groups.empty() ? "" : ", ") + g.substr(0, g.find(' '));
  text += "Every key, with its meaning and range: " + program + " --help-keys [GROUP], GROUP" +
          " one of " + groups + " (docs/configuration.md: the same reference).\n";
  // Lines wrapped at 92 columns (the list of groups is longer than one).
  std::string wrapped, line;
  std::istringstream lines(text);
  while (std::getline(lines, line)) {
    while (line.size() > 92) {
      const size_t cut = line.rfind(' ', 92);
      if (cut == std::string::npos || cut == 0) break;
      wrapped += line.substr(0, cut) + "\n";
      line = "  " + line.substr(cut + 1);
    }
    wrapped += line + "\n";
  }
  return wrapped;
}

int AnswerHelpKeys(const std::string& program, const std::string& group) {
  std::string keys;
  try {
    keys = ConfigHelpText(group);
  } catch (const InputError& e) {
    std::cerr << program << ": " << ToValidUtf8(e.what()) << "\n";
    return 2;
  }
  std::cout << "Configuration keys (Config.txt: one 'Key: value' per line, '#' comments;\n"
               "or --set Key=Value):\n"
            << keys;
  return 0;
}

int AnswerWithoutRunning(const CommandLine& command_line, const std::string& usage_error,
                         const std::string& program, const ProgramHelp& help,
                         const std::string& version_line) {
  if (command_line.help) {
    std::cout << FormatProgramHelp(program, help);
    return 0;
  }
  if (command_line.help_keys) return AnswerHelpKeys(program, command_line.help_group);
  if (command_line.help_markdown) {
    std::cout << ConfigMarkdownReference();
    return 0;
  }
  if (command_line.version) {
    std::cout << version_line << "\n";
    return 0;
  }
  if (!usage_error.empty()) {
    std::cerr << ToValidUtf8(usage_error) << "\n";
    return 2;
  }
  return -1;
}

Config ConfigOf(const CommandLine& command_line) {
  Config config =
      command_line.config_path.empty() ? Config() : LoadConfig(command_line.config_path);
  for (const auto& o : command_line.overrides) ApplyOverride(config, o);
  return config;
}

int RunConfigProgram(
    int argc, const char* const* argv, const char* program, const ProgramHelp& help,
    const std::string& version_line,
    const std::function<int(const Config&, const CommandLine&, ProgressReporter&)>& body,
    const std::vector<std::string>& value_options, bool spreads_over_processes) {
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  InstallInterruptCleanup(program);
  // Under mpirun, process 0 speaks for the run (cluster.h): the others print nothing, neither
  // answers (--help) nor progress, notes, reports or the errors every process meets alike.
  Cluster& cluster = Cluster::Get();
  if (cluster.LaunchRank() > 0) {
    std::cout.setstate(std::ios::badbit);
    std::cerr.setstate(std::ios::badbit);
    SilenceInterruptMessage();
  }
  CommandLine cl;
  const std::string usage_error = ParseCommandLine(argc, argv, program, cl, value_options);
  const int answered = AnswerWithoutRunning(cl, usage_error, program, help, version_line);
  if (answered >= 0) return answered;
  const int status = RunProgram(program, [&]() -> int {
    const Config config = ConfigOf(cl);
    if (cl.print_config) {
      std::cout << FormatConfig(config);
      return 0;
    }
    if (cluster.LaunchSize() > 1) {
      if (!spreads_over_processes)
        throw InputError(std::string(program) + " runs as one process, but mpirun started " +
                         std::to_string(cluster.LaunchSize()) +
                         "; expected one (Test_OpenABLE spreads a run over processes)");
      cluster.Connect();
    }
    ProgressReporter progress(std::cerr, !cl.quiet, IsTerminal(2));
    try {
      return body(config, cl, progress);
    } catch (const ClusterFailure& e) {
      // Every process throws it: process 0 says it, once.
      if (e.InputErrorCause()) throw InputError(e.what());
      throw std::runtime_error(e.what());
    } catch (const std::exception& e) {
      if (!cluster.Collective()) throw;
      // This process alone failed where the others may wait for it: it says so itself (even
      // when not process 0) and ends the run.
      const bool input = dynamic_cast<const InputError*>(&e) != nullptr;
      std::fprintf(stderr, "%s: %s%s (%s)\n", program,
                   input ? "error: " : "internal error (please report): ",
                   ToValidUtf8(e.what()).c_str(), cluster.Name(cluster.Rank()).c_str());
      std::fflush(stderr);
      cluster.Abort(input ? kExitInputError : kExitInternalError);
    }
  });
  cluster.Disconnect();
  return status;
}

}  // namespace openable
