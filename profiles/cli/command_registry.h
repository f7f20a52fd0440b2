#pragma once
/// Self-registering subcommands of the `brickworld` CLI. Each command lives in its own
/// file under profiles/cli/ and registers itself with a static CommandRegistration:
///
///   static bw::cli::CommandRegistration reg{"batch-bench", "Per-object vs batched render
///       submission", [](CLI::App& cmd) { ...add options...; return [=] { ...run...; }; }};
///
/// The setup function adds options to the subcommand and returns the action to run when the
/// subcommand is chosen; the action returns the process exit code.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace bw::cli {

using CommandAction = std::function<int()>;
using CommandSetup = std::function<CommandAction(CLI::App&)>;

struct CommandInfo {
  std::string name;
  std::string description;
  CommandSetup setup;
};

/// All registered commands (in registration order; main sorts them by name).
std::vector<CommandInfo>& commandRegistry();

struct CommandRegistration {
  CommandRegistration(std::string name, std::string description, CommandSetup setup) {
    commandRegistry().push_back({std::move(name), std::move(description), std::move(setup)});
  }
};

}  // namespace bw::cli
