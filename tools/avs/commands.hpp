// Each `avs` subcommand adds itself to the CLI11 app; one file per command family.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace avs::cli {

void add_launch_command(CLI::App& app);
void add_container_command(CLI::App& app);
void add_check_command(CLI::App& app);
void add_components_command(CLI::App& app);
void add_topic_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_demo_command(CLI::App& app);

/// Runs `avs launch` on `file` (containers of `host` only, if set); returns the exit status.
int launch_graph(const std::string& file, const std::vector<std::string>& words,
                 const std::string& host);

/// Exit status set by the command that ran (CLI11 callbacks cannot return one).
int& exit_status();

}  // namespace avs::cli
