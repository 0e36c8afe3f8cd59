// `handcentric`: the command line. Plain `handcentric` prints the main report; the subcommands
// are listed in commands.cpp, each defined in its own cmd_*.cpp.
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "commands.hpp"
#include "handcentric/core/errors.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "handcentric: executable claims of hand-centric SE(3)-equivariant behavior cloning.\n"
      "Without a subcommand it prints the main report."};
  app.require_subcommand(0, 1);
  int exit_code = 0;
  for (const auto& command : handcentric::apps::commands()) command.add(app, exit_code);
  try {
    app.parse(argc, argv);
    if (app.get_subcommands().empty()) exit_code = handcentric::apps::run_main_report(std::cout);
  } catch (const CLI::ParseError& e) {
    const int cli_code = app.exit(e);
    return cli_code == 0 ? 0 : 2;  // --help exits 0; usage errors exit 2
  } catch (const handcentric::Error& e) {
    std::cerr << "handcentric: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "handcentric: internal error: " << e.what() << "\n";
    return 1;
  }
  return exit_code;
}
