// Helpers for tests that run the `avs` program (AVS_PROGRAM) and read what it wrote.
#pragma once

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>

namespace avs::testing {

inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs `AVS_DOMAIN_ID=domain avs ARGS > out 2> err`; returns the exit status (-1 if the
/// program did not exit normally).
inline int run_avs(const std::string& args, int domain, const std::filesystem::path& out,
                   const std::filesystem::path& err) {
  const std::string command = "AVS_DOMAIN_ID=" + std::to_string(domain) + " " +
                              std::string(AVS_PROGRAM) + " " + args + " > " + out.string() +
                              " 2> " + err.string();
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// The number after `"key": ` in `json` (null -> NaN); throws when the key is missing.
inline double json_number(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\":\\s*(null|[-0-9.eE+]+)");
  std::smatch m;
  if (!std::regex_search(json, m, re)) throw std::runtime_error("no key " + key);
  return m[1] == "null" ? std::nan("") : std::stod(m[1]);
}

}  // namespace avs::testing
