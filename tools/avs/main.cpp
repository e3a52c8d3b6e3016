// avs: the command line. Subcommands live in their own files (launch.cpp, topic.cpp, ...).
#include <iostream>
#include <optional>

#include "commands.hpp"

namespace avs::cli {
int& exit_status() {
  static int status = 0;
  return status;
}
}  // namespace avs::cli

int main(int argc, char** argv) {
  // Building the commands reads the environment too (AVS_DOMAIN_ID for --domain's default): a bad
  // value is an error message and status 1, like a bad option, never an abort.
  try {
    avs::cli::Command app{
        "avs: active high-speed 3-D vision (Gray-code depth at 500 Hz, visual servoing, "
        "model matching) as a graph of components over DDS"};
    app.require_subcommand(1);
    app.version("avs " AVS_VERSION);
    avs::cli::add_demo_command(app);
    avs::cli::add_launch_command(app);
    avs::cli::add_check_command(app);
    avs::cli::add_container_command(app);
    avs::cli::add_components_command(app);
    avs::cli::add_topic_command(app);
    avs::cli::add_bench_command(app);
    for (const auto& [name, adder] : avs::cli::registered_commands()) adder(app);
    if (const std::optional<int> status = app.parse_or_explain(argc, argv)) return *status;
  } catch (const std::exception& e) {
    std::cerr << "avs: " << e.what() << "\n";
    return 1;
  }
  return avs::cli::exit_status();
}
