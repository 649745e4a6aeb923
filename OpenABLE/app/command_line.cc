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
    SilenceInterruptMessage();
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
