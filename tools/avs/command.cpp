// The CLI11 facade of command.hpp: the one file of the `avs` program that compiles CLI11.
#include "command.hpp"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include <CLI/CLI.hpp>

namespace avs::cli {
namespace {

/// Every floating-point option refuses NaN and the infinities (`--wait nan` used to wait
/// forever, `--rate inf` to spin): the option's range, if any, is checked after this.
CLI::Validator finite_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0') return {};  // not a number: CLI11 says so
        return std::isfinite(v) ? std::string() : "a finite number is needed, got " + text;
      },
      "", "FINITE");
}

/// A bound as a person writes it: "232", "0.1", "3600" (this file links nothing of avs).
std::string bound_text(double v) {
  // Whole bounds as integers ("1000000000000000", not "1e+15"), as `avs components` prints.
  if (std::floor(v) == v && std::abs(v) < 9.0e15) return std::to_string(static_cast<long long>(v));
  std::ostringstream out;
  out.precision(15);
  out << v;
  return out.str();
}

}  // namespace

Option* Option::required() {
  option_->required();
  return this;
}

Option* Option::capture_default_str() {
  option_->capture_default_str();
  return this;
}

Option* Option::optional_value() {
  option_->expected(0, 1);
  return this;
}

bool Option::given() const {
  return option_->count() > 0;
}

Option* Option::check_member(std::vector<std::string> allowed) {
  option_->check(CLI::IsMember(std::move(allowed)));
  return this;
}

Option* Option::check_range(double min, double max) {
  // CLI11 describes a range as FLOAT even on an integer option ("INT:FLOAT in [0 - 232]"):
  // the option's own type with the bounds instead, "INT in [0, 232]".
  const std::string type = option_->get_type_name();
  option_->check(CLI::Range(min, max).description(""));
  option_->type_name(type + " in [" + bound_text(min) + ", " + bound_text(max) + "]");
  return this;
}

Option* Option::check_existing_file() {
  option_->check(CLI::ExistingFile);
  return this;
}

Command::Command(std::string description)
    : owned_(std::make_unique<CLI::App>(std::move(description))), app_(owned_.get()) {}

Command::Command(CLI::App* app) : app_(app) {}

Command::~Command() = default;

Command* Command::version(std::string text) {
  app_->set_version_flag("--version", std::move(text));
  return this;
}

Command* Command::add_subcommand(std::string name, std::string description) {
  // The constructor is private: no make_unique.
  subcommands_.push_back(std::unique_ptr<Command>(
      new Command(app_->add_subcommand(std::move(name), std::move(description)))));
  return subcommands_.back().get();
}

Option* Command::keep(CLI::Option* option) {
  options_.push_back(std::make_unique<Option>(option));
  return options_.back().get();
}

Option* Command::add_option(std::string name, std::string& value, std::string description) {
  return keep(app_->add_option(std::move(name), value, std::move(description)));
}

Option* Command::add_option(std::string name, std::vector<std::string>& values,
                            std::string description) {
  return keep(app_->add_option(std::move(name), values, std::move(description)));
}

Option* Command::add_option(std::string name, std::filesystem::path& value,
                            std::string description) {
  return keep(app_->add_option(std::move(name), value, std::move(description)));
}

Option* Command::add_option(std::string name, double& value, std::string description) {
  return keep(
      app_->add_option(std::move(name), value, std::move(description))->check(finite_number()));
}

Option* Command::add_option(std::string name, int& value, std::string description) {
  return keep(app_->add_option(std::move(name), value, std::move(description)));
}

Option* Command::add_option(std::string name, unsigned& value, std::string description) {
  return keep(app_->add_option(std::move(name), value, std::move(description)));
}

Option* Command::add_option(std::string name, long& value, std::string description) {
  return keep(app_->add_option(std::move(name), value, std::move(description)));
}

Option* Command::add_option(std::string name, unsigned long& value, std::string description) {
  return keep(app_->add_option(std::move(name), value, std::move(description)));
}

Option* Command::add_flag(std::string name, bool& value, std::string description) {
  return keep(app_->add_flag(std::move(name), value, std::move(description)));
}

Command* Command::require_subcommand(int count) {
  app_->require_subcommand(count);
  return this;
}

Command* Command::callback(std::function<void()> run) {
  app_->callback(std::move(run));
  return this;
}

Command* Command::footer(std::string text) {
  app_->footer(std::move(text));
  return this;
}

Command* Command::group(std::string name) {
  app_->group(std::move(name));
  return this;
}

Command* Command::prefix_command() {
  app_->prefix_command();
  return this;
}

std::vector<std::string> Command::remaining() const {
  return app_->remaining();
}

Command* Command::own_help_flag(bool& value, std::string description) {
  app_->set_help_flag();
  add_flag("-h,--help", value, std::move(description));
  return this;
}

std::string Command::help_text() const {
  // With the parents' names, as CLI11's own --help prints it ("Usage: avs bench ..."); the
  // program's own name is argv[0] (a path) or empty: "avs" as the docs write it.
  std::string parents;
  for (const CLI::App* a = app_->get_parent(); a != nullptr; a = a->get_parent()) {
    const std::string name = a->get_parent() == nullptr ? "avs" : a->get_name();
    parents = name + (parents.empty() ? "" : " " + parents);
  }
  return app_->help(parents);
}

std::size_t Command::count(const std::string& name) const {
  return app_->count(name);
}

void Command::parse(int argc, const char* const* argv) {
  app_->parse(argc, argv);
}

std::optional<int> Command::parse_or_explain(int argc, const char* const* argv) {
  // A first word that is no command: say so and list the commands (CLI11 would only say
  // "A subcommand is required").
  if (argc > 1 && argv[1][0] != '-') {
    const auto all = app_->get_subcommands([](CLI::App*) { return true; });
    bool known = all.empty();
    std::string names;
    for (const CLI::App* sub : all) {
      known = known || sub->check_name(argv[1]);
      if (!sub->get_group().empty()) names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::cerr << "avs: unknown command '" << argv[1] << "'; commands: " << names
                << " (--help says more)\n";
      return 2;
    }
  }
  try {
    app_->parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app_->exit(e);
  }
  return std::nullopt;
}

}  // namespace avs::cli
