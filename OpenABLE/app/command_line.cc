#include "OpenABLE/app/command_line.h"

#include <algorithm>
#include <cstdio>
#include <iostream>

#include <opencv2/core/utils/logger.hpp>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/interrupt.h"
#include "OpenABLE/base/program.h"
#include "OpenABLE/cluster/cluster.h"

namespace openable {

std::string ParseCommandLine(int argc, const char* const* argv, const std::string& program,
                             CommandLine& out, const std::vector<std::string>& value_options) {
  out = CommandLine();
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto own = std::find_if(value_options.begin(), value_options.end(),
                                  [&a](const std::string& o) {
                                    return a == o || a.rfind(o + "=", 0) == 0;
                                  });
    if (own != value_options.end()) {
      if (a != *own) {
        out.options.emplace_back(*own, a.substr(own->size() + 1));
      } else if (i + 1 >= argc) {
        return program + ": " + a + " needs a value (see --help)";
      } else {
        out.options.emplace_back(*own, argv[++i]);
      }
    } else if (a == "-h" || a == "--help") {
      out.help = true;
    } else if (a == "--help-markdown") {
      out.help_markdown = true;
    } else if (a == "--version") {
      out.version = true;
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
  if (!out.help && !out.help_markdown && !out.version && out.config_path.empty() &&
      out.overrides.empty())
    return program + ": no configuration given; expected " + program +
           " Config.txt or --set Key=Value (see --help)";
  return "";
}

int AnswerWithoutRunning(const CommandLine& command_line, const std::string& usage_error,
                         const std::string& usage, const std::string& version_line) {
  if (command_line.help) {
    std::cout << usage << ConfigHelpText();
    return 0;
  }
  if (command_line.help_markdown) {
    std::cout << ConfigMarkdownReference();
    return 0;
  }
  if (command_line.version) {
    std::cout << version_line << "\n";
    return 0;
  }
  if (!usage_error.empty()) {
    std::cerr << usage_error << "\n";
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
    int argc, const char* const* argv, const char* program, const std::string& usage,
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
  }
  CommandLine cl;
  const std::string usage_error = ParseCommandLine(argc, argv, program, cl, value_options);
  const int answered = AnswerWithoutRunning(cl, usage_error, usage, version_line);
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
                   input ? "error: " : "internal error (please report): ", e.what(),
                   cluster.Name(cluster.Rank()).c_str());
      std::fflush(stderr);
      cluster.Abort(input ? kExitInputError : kExitInternalError);
    }
  });
  cluster.Disconnect();
  return status;
}

}  // namespace openable
