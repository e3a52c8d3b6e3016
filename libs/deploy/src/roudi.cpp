#include "avs/deploy/roudi.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "avs/runtime/error.hpp"
#include "avs/runtime/process.hpp"

namespace avs::deploy {
namespace {

namespace fs = std::filesystem;

// Mempools (chunk size x count): small samples, and 512 KiB chunks for 256 KiB images with
// room for the reader histories of a few image subscribers (Debian's example has 50).
constexpr const char* kConfig = R"([general]
version = 1

[[segment]]

[[segment.mempool]]
size = 128
count = 10000

[[segment.mempool]]
size = 1024
count = 5000

[[segment.mempool]]
size = 16384
count = 1000

[[segment.mempool]]
size = 131072
count = 200

[[segment.mempool]]
size = 524288
count = 200

[[segment.mempool]]
size = 1048576
count = 30

[[segment.mempool]]
size = 4194304
count = 10
)";

bool alive(pid_t pid) {
  int status = 0;
  return waitpid(pid, &status, WNOHANG) == 0;
}

}  // namespace

std::string Roudi::find_executable() {
  const char* path = std::getenv("PATH");
  std::string dirs = path != nullptr ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const fs::path candidate = fs::path(dirs.substr(start, end - start)) / "iox-roudi";
    if (access(candidate.c_str(), X_OK) == 0) return candidate.string();
    start = end + 1;
  }
  return "";
}

bool Roudi::running() {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/proc", ec)) {
    std::ifstream comm(entry.path() / "comm");
    std::string name;
    if (comm && std::getline(comm, name) && name == "iox-roudi") return true;
  }
  return false;
}

Roudi::Roudi(double timeout_s) {
  if (running()) {
    description_ = "an already running RouDi";
    return;
  }
  const std::string exe = find_executable();
  if (exe.empty()) {
    throw runtime::Error(
        "shared memory needs iceoryx's RouDi: iox-roudi is not on PATH (Debian package "
        "'iceoryx': apt-get install iceoryx)");
  }
  char dir_template[] = "/tmp/avs_roudi.XXXXXX";
  if (mkdtemp(dir_template) == nullptr) throw runtime::Error("mkdtemp for the RouDi config failed");
  config_dir_ = dir_template;
  const std::string config = config_dir_ + "/roudi.toml";
  std::ofstream(config) << kConfig;
  std::vector<std::string> args = {exe, "-c", config, "-l", "warning"};
  description_ = exe + " -c " + config;
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string log_path = config_dir_ + "/roudi.log";
  const int log_fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log_fd < 0) throw runtime::Error("cannot create " + log_path);
  const pid_t launcher = getpid();
  pid_ = fork();
  if (pid_ < 0) throw runtime::Error("fork for iox-roudi failed");
  if (pid_ == 0) {
    runtime::die_with_parent(launcher);
    // RouDi's output goes to a file: it says when it is ready for clients.
    dup2(log_fd, 1);
    dup2(log_fd, 2);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  close(log_fd);
  const fs::path log = fs::path(config_dir_) / "roudi.log";
  // RouDi is up when it says "RouDi is ready for clients" (its segments exist before that).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  auto ready = [&] {
    std::ifstream in(log);
    std::string line;
    while (std::getline(in, line)) {
      if (line.find("ready for clients") != std::string::npos) return true;
    }
    return false;
  };
  while (!ready()) {
    if (!alive(pid_)) {
      pid_ = -1;
      throw runtime::Error("iox-roudi ended at start-up (" + description_ + ")");
    }
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
      pid_ = -1;
      throw runtime::Error("iox-roudi did not say it was ready within " +
                           std::to_string(timeout_s) + " s (" + log.string() + ")");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

Roudi::~Roudi() {
  if (pid_ > 0) {
    kill(pid_, SIGTERM);
    for (int i = 0; i < 100 && alive(pid_); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    if (alive(pid_)) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  std::error_code ec;
  if (!config_dir_.empty()) fs::remove_all(config_dir_, ec);
}

}  // namespace avs::deploy
