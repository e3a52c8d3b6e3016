// Child processes for the bag tests: the real `avs` program (launch, bag record/play) with
// the test's own DDS domain (tests/support), output captured to a file.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "avs/testing/child_process.hpp"
#include "avs/testing/test_domain.hpp"

namespace avs::bag::test {

inline std::vector<std::string> avs_words(const std::vector<std::string>& words) {
  std::vector<std::string> args = {AVS_BINARY};
  args.insert(args.end(), words.begin(), words.end());
  return args;
}

/// A child process running `avs WORDS...` on this test's DDS domain; stdout+stderr go to
/// `log`. Stopped when destroyed if still running (its whole process group).
class AvsProcess : public avs::testing::ChildProcess {
 public:
  AvsProcess(const std::vector<std::string>& words, const std::filesystem::path& log)
      : ChildProcess(avs_words(words),
                     {"AVS_DOMAIN_ID=" + std::to_string(avs::testing::test_domain())}, log) {}
};

inline std::string source_dir() {
  const char* env = std::getenv("AVS_SOURCE_DIR");
  return env != nullptr ? env : AVS_SOURCE_DIR_DEFAULT;
}

}  // namespace avs::bag::test
