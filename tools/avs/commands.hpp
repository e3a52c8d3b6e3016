// Each `avs` subcommand adds itself to the program's Command (command.hpp, a facade over
// CLI11 so that the command files do not compile CLI11); one file per command family.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "command.hpp"

namespace avs::cli {

void add_launch_command(Command& app);
void add_container_command(Command& app);
void add_check_command(Command& app);
void add_components_command(Command& app);
void add_topic_command(Command& app);
/// `avs topic pub` (topic_pub.cpp), added by add_topic_command.
void add_topic_pub_command(Command* topic);
void add_bench_command(Command& app);
void add_demo_command(Command& app);

/// Subcommands in files of their own register themselves, so adding a command never edits
/// main.cpp:  AVS_REGISTER_COMMAND(add_bag_command);  CLI11 lists commands in the order they
/// are added; registered ones come after the built-in ones, sorted by function name.
using CommandAdder = void (*)(Command&);
struct CommandRegistration {
  CommandRegistration(const char* name, CommandAdder adder);
};
/// (name, adder) pairs of every registered command, sorted by name.
std::vector<std::pair<std::string, CommandAdder>> registered_commands();

#define AVS_REGISTER_COMMAND(adder)                                            \
  namespace {                                                                   \
  const ::avs::cli::CommandRegistration avs_command_registration_##adder{#adder, \
                                                                         &adder}; \
  }

/// Runs `avs launch` on `file` (containers of `host` only, if set); returns the exit status.
int launch_graph(const std::string& file, const std::vector<std::string>& words,
                 const std::string& host);

/// Exit status set by the command that ran (CLI11 callbacks cannot return one).
int& exit_status();

}  // namespace avs::cli
