// Helpers for tests that run the `avs` program (AVS_PROGRAM) and read what it wrote.
#pragma once

#include <cmath>
#include <filesystem>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

#include "avs/testing/child_process.hpp"
#include "avs/testing/test_domain.hpp"

namespace avs::testing {

/// Runs `avs WORDS...` (AVS_PROGRAM) on this test's DDS domain, stdout to `out`, stderr to
/// `err`; the exit code, or -1 if the program did not exit normally.
inline int run_avs(std::vector<std::string> words, const std::filesystem::path& out,
                   const std::filesystem::path& err) {
  words.insert(words.begin(), AVS_PROGRAM);
  return run_program(std::move(words), {"AVS_DOMAIN_ID=" + std::to_string(test_domain())}, out,
                     err);
}

/// The number after `"key": ` in `json` (null -> NaN); throws when the key is missing.
inline double json_number(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\":\\s*(null|[-0-9.eE+]+)");
  std::smatch m;
  if (!std::regex_search(json, m, re)) throw std::runtime_error("no key " + key);
  return m[1] == "null" ? std::nan("") : std::stod(m[1]);
}

}  // namespace avs::testing
