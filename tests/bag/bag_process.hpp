// Child processes for the bag tests: the real `avs` program (launch, bag record/play) with
// its own DDS domain, output captured to a file.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace avs::bag::test {

/// A child process running `avs WORDS...` with AVS_DOMAIN_ID=domain; stdout+stderr go to
/// `log`. Stopped when destroyed if still running.
class AvsProcess {
 public:
  AvsProcess(const std::vector<std::string>& words, int domain, const std::filesystem::path& log)
      : log_(log) {
    std::vector<std::string> args = {AVS_BINARY};
    args.insert(args.end(), words.begin(), words.end());
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<std::string> env_strings;
    for (char** e = environ; *e != nullptr; ++e) {
      if (std::string(*e).rfind("AVS_DOMAIN_ID=", 0) != 0) env_strings.emplace_back(*e);
    }
    env_strings.push_back("AVS_DOMAIN_ID=" + std::to_string(domain));
    std::vector<char*> envp;
    for (auto& e : env_strings) envp.push_back(e.data());
    envp.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    // Own process group: the containers `avs launch` starts are stopped with it.
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attr, 0);
    const int rc = posix_spawn(&pid_, args[0].c_str(), &actions, &attr, argv.data(), envp.data());
    posix_spawnattr_destroy(&attr);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) pid_ = 0;
  }
  /// SIGTERM to the process group (launcher and containers), SIGKILL after 5 s.
  ~AvsProcess() {
    if (pid_ <= 0) return;
    kill(-pid_, SIGTERM);
    if (!exited_ && wait(std::chrono::milliseconds(5000)) < 0) {
      kill(-pid_, SIGKILL);
      int status = 0;
      waitpid(pid_, &status, 0);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    kill(-pid_, SIGKILL);  // anything of the group still there
  }
  AvsProcess(const AvsProcess&) = delete;
  AvsProcess& operator=(const AvsProcess&) = delete;

  bool started() const { return pid_ > 0; }
  void signal(int sig) const { kill(pid_, sig); }

  /// Waits up to `timeout` for the exit; returns the raw wait status, or -1 on timeout.
  int wait(std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      int status = 0;
      const pid_t r = waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        exited_ = true;
        return status;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return -1;
  }

  std::string output() const {
    std::ifstream in(log_);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }

 private:
  std::filesystem::path log_;
  pid_t pid_ = 0;
  bool exited_ = false;
};

inline std::string source_dir() {
  const char* env = std::getenv("AVS_SOURCE_DIR");
  return env != nullptr ? env : AVS_SOURCE_DIR_DEFAULT;
}

}  // namespace avs::bag::test
