// The table of self-registered `avs` subcommands (AVS_REGISTER_COMMAND, commands.hpp).
#include <algorithm>

#include "commands.hpp"

namespace avs::cli {

namespace {
std::vector<std::pair<std::string, CommandAdder>>& command_table() {
  static std::vector<std::pair<std::string, CommandAdder>> table;
  return table;
}
}  // namespace

CommandRegistration::CommandRegistration(const char* name, CommandAdder adder) {
  command_table().emplace_back(name, adder);
}

std::vector<std::pair<std::string, CommandAdder>> registered_commands() {
  auto table = command_table();
  std::sort(table.begin(), table.end());
  return table;
}

}  // namespace avs::cli
