#include "harness/cli/command.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <thread>

namespace harness {

int PrintFailure(const char* command, int exit_code, const std::string& message) {
  std::fprintf(stderr, "vobench %s: %s\n", command, message.c_str());
  return exit_code;
}

int DefaultJobs() { return std::max(1u, std::thread::hardware_concurrency()); }

int RunGivenCommand(const std::vector<Command>& commands) {
  for (const Command& c : commands)
    if (c.app->parsed()) return c.run();
  return kExitOk;
}

CLI::Validator NonEmpty() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        return text.empty() ? "empty: name a folder (or leave the option out for the default)"
                            : std::string();
      },
      "DIR");
}

CLI::Validator AtLeast(long min) {
  const std::string bound = std::to_string(min);
  return CLI::Validator(
      [min, bound](std::string& text) -> std::string {
        long value = 0;
        size_t used = 0;
        try {
          value = std::stol(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != text.size())
          return "expected an integer >= " + bound + ", got '" + text + "'";
        if (value < min) return "must be >= " + bound + ", got " + text;
        return std::string();
      },
      "INT>=" + bound);
}

int ParseCommandLine(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
    return -1;
  } catch (const CLI::Success& e) {  // --help
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // The subcommands parsed so far name the command in the message ("vobench suite merge").
    std::string command = "vobench";
    for (const CLI::App* a = &app; !a->get_subcommands().empty();) {
      a = a->get_subcommands().front();
      command += " " + a->get_name();
    }
    std::string message = e.what();
    for (char& c : message)
      if (c == '\n' || c == '\r') c = ' ';
    while (!message.empty() && message.back() == ' ') message.pop_back();
    std::fprintf(stderr, "%s: %s (see %s --help)\n", command.c_str(), message.c_str(),
                 command.c_str());
    return kExitBadInput;
  }
}

}  // namespace harness
