// The `avs` command line's one view of CLI11: a Command is a CLI::App (the program or one of
// its subcommands), an Option one of its options. The facade is not a template, so only
// command.cpp compiles CLI11's header-only code (about 10 s of CPU in every file that
// includes <CLI/CLI.hpp>); the command files include this header instead. Each add_option
// overload calls CLI11's add_option with the same variable type, so the help text, the
// type names (TEXT, INT, FLOAT, ...) and the parsing are CLI11's own.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace avs::cli {

/// One option of a Command; the setters return `this` so that they chain as in CLI11.
class Option {
 public:
  explicit Option(CLI::Option* option) : option_(option) {}

  Option* required();
  Option* capture_default_str();
  /// The value must be one of `allowed` (CLI::IsMember).
  Option* check_member(std::vector<std::string> allowed);
  /// The value must lie in [min, max] (CLI::Range).
  Option* check_range(double min, double max);
  /// The value must name an existing file (CLI::ExistingFile).
  Option* check_existing_file();
  /// The value may be left out (`--realtime` or `--realtime 0.5`): then it is empty.
  Option* optional_value();
  /// Whether the option was on the command line.
  bool given() const;

 private:
  CLI::Option* option_;
};

/// The program (constructed with its description) or a subcommand (from add_subcommand).
/// Subcommands and options live as long as the program's Command.
class Command {
 public:
  /// The program: owns the CLI::App.
  explicit Command(std::string description);
  ~Command();
  Command(const Command&) = delete;
  Command& operator=(const Command&) = delete;
  Command(Command&&) = delete;
  Command& operator=(Command&&) = delete;

  Command* add_subcommand(std::string name, std::string description);
  /// `--version` prints `text` and exits.
  Command* version(std::string text);

  Option* add_option(std::string name, std::string& value, std::string description = "");
  Option* add_option(std::string name, std::vector<std::string>& values,
                     std::string description = "");
  Option* add_option(std::string name, std::filesystem::path& value, std::string description = "");
  Option* add_option(std::string name, double& value, std::string description = "");
  Option* add_option(std::string name, int& value, std::string description = "");
  Option* add_option(std::string name, unsigned& value, std::string description = "");
  Option* add_option(std::string name, long& value, std::string description = "");
  Option* add_option(std::string name, unsigned long& value, std::string description = "");
  Option* add_flag(std::string name, bool& value, std::string description = "");

  Command* require_subcommand(int count);
  Command* callback(std::function<void()> run);
  Command* footer(std::string text);
  /// "" hides the command from its parent's --help.
  Command* group(std::string name);
  /// Words after the positionals are left for remaining() (CLI::App::prefix_command).
  Command* prefix_command();
  std::vector<std::string> remaining() const;
  /// Replaces CLI11's -h/--help (print and exit) by a flag the callback reads, for a command
  /// that passes help on (`avs bench NAME --help`); help_text() is what --help would print.
  Command* own_help_flag(bool& value, std::string description);
  std::string help_text() const;
  /// How many times the option `name` (e.g. "--width") was given.
  std::size_t count(const std::string& name) const;

  /// Parses the command line and runs the chosen callbacks; throws CLI::ParseError (also for
  /// --help) and whatever a callback throws.
  void parse(int argc, const char* const* argv);
  /// parse(), with a command-line error or --help printed the way CLI11 prints it: returns
  /// CLI11's exit code for those (0 for --help), nothing when the command line was run.
  std::optional<int> parse_or_explain(int argc, const char* const* argv);

 private:
  explicit Command(CLI::App* app);
  Option* keep(CLI::Option* option);

  std::unique_ptr<CLI::App> owned_;  ///< set for the program only
  CLI::App* app_;
  std::vector<std::unique_ptr<Command>> subcommands_;
  std::vector<std::unique_ptr<Option>> options_;
};

}  // namespace avs::cli
