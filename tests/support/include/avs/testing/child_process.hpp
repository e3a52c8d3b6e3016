// Child programs for tests, started one way (posix_spawn, no shell): the argument words as
// given, the test's environment with some variables replaced, stdout and stderr to files.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace avs::testing {

class ChildProcess {
 public:
  /// Starts `argv` (argv[0] a path) in a process group of its own, with `env` ("NAME=VALUE",
  /// replacing the test's NAME) on top of the test's environment, stdin from /dev/null, stdout
  /// to `output` and stderr to `error_output` (or `output` too). started() says whether it ran.
  ChildProcess(std::vector<std::string> argv, const std::vector<std::string>& env,
               std::filesystem::path output,
               std::optional<std::filesystem::path> error_output = std::nullopt);
  /// SIGTERM to the process group (a launcher and its containers), SIGKILL after 5 s.
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  bool started() const { return pid_ > 0; }
  void signal(int sig) const;
  /// Waits up to `timeout` for the exit; the raw wait status, or -1 on timeout.
  int wait(std::chrono::milliseconds timeout);
  /// Waits for the exit; the exit code, or -1 when it did not exit normally (or never started).
  int exit_code();
  /// What it wrote to `output` so far.
  std::string output() const;

 private:
  std::filesystem::path output_;
  pid_t pid_ = 0;
  bool exited_ = false;
  int status_ = 0;
};

/// Runs `argv` to its end (see ChildProcess); the exit code, or -1 when it did not exit normally.
int run_program(std::vector<std::string> argv, const std::vector<std::string>& env,
                const std::filesystem::path& output,
                std::optional<std::filesystem::path> error_output = std::nullopt);

/// The whole file ("" when it cannot be read).
std::string read_file(const std::filesystem::path& path);

}  // namespace avs::testing
