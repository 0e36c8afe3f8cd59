#include "commands.hpp"

#include <algorithm>

namespace handcentric::apps {
namespace {

// Function-local statics: safe to use from other translation units' static initializers.
std::vector<RegisteredCommand>& command_list() {
  static std::vector<RegisteredCommand> list;
  return list;
}

std::vector<RegisteredSection>& section_list() {
  static std::vector<RegisteredSection> list;
  return list;
}

}  // namespace

CommandRegistration::CommandRegistration(std::string name, AddCommand add) {
  command_list().push_back({std::move(name), add});
}

std::vector<RegisteredCommand> registered_commands() {
  auto list = command_list();
  std::sort(list.begin(), list.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  return list;
}

ReportSection::ReportSection(int order, std::string name, RunSection run) {
  section_list().push_back({order, std::move(name), std::move(run)});
}

std::vector<RegisteredSection> report_sections() {
  auto list = section_list();
  std::stable_sort(list.begin(), list.end(),
                   [](const auto& a, const auto& b) { return a.order < b.order; });
  return list;
}

int run_main_report(std::ostream& out, const ReportOptions& options) {
  int status = 0;
  for (const RegisteredSection& section : report_sections()) {
    if (section.run(out, options) != 0) status = 1;
    out << "\n";
  }
  return status;
}

}  // namespace handcentric::apps
