// brickworld: headless stress runs, sweeps and micro-benchmark tables.
#include <algorithm>
#include <exception>
#include <iostream>
#include <memory>
#include <string>

#include "cli/command_registry.h"

namespace bw::cli {
std::vector<CommandInfo>& commandRegistry() {
  static std::vector<CommandInfo> registry;
  return registry;
}
}  // namespace bw::cli

int main(int argc, char** argv) {
  using namespace bw::cli;
  CLI::App app{"brickworld: a physics world for huge editable brick structures, run headless"};
  app.require_subcommand(1);
  auto& registry = commandRegistry();
  std::sort(registry.begin(), registry.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  std::vector<std::pair<CLI::App*, CommandAction>> actions;
  for (auto& c : registry) {
    CLI::App* sub = app.add_subcommand(c.name, c.description);
    actions.emplace_back(sub, c.setup(*sub));
  }
  // An unknown first word: CLI11 would only say "A subcommand is required".
  if (argc > 1 && argv[1][0] != '-' &&
      std::none_of(registry.begin(), registry.end(), [&](const CommandInfo& c) { return c.name == argv[1]; })) {
    std::string names;
    for (const auto& c : registry) names += (names.empty() ? "" : ", ") + c.name;
    std::cerr << "brickworld: error: unknown subcommand '" << argv[1] << "' (expected one of: " << names << "; see --help)\n";
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    for (auto& [sub, action] : actions)
      if (sub->parsed()) return action();
  } catch (const std::exception& e) {
    std::cerr << "brickworld: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
