#include "avs_child.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>

#include "avs/runtime/error.hpp"

extern char** environ;

namespace avs::cli {

namespace fs = std::filesystem;

AvsChild::AvsChild(const std::vector<std::string>& args, const std::string& cyclone_xml, int domain,
                   const std::filesystem::path& log, const std::string& who) {
  std::vector<std::string> env;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string_view s(*e);
    if (s.rfind("CYCLONEDDS_URI=", 0) != 0 && s.rfind("AVS_DOMAIN_ID=", 0) != 0) {
      env.emplace_back(s);
    }
  }
  env.push_back("CYCLONEDDS_URI=" + cyclone_xml);
  env.push_back("AVS_DOMAIN_ID=" + std::to_string(domain));
  std::vector<std::string> argv_s = args;
  argv_s.insert(argv_s.begin(), "avs");
  std::vector<char*> argv, envp;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  for (auto& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  const int rc = posix_spawn(&pid_, "/proc/self/exe", &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    pid_ = -1;
    throw runtime::Error(who + ": cannot start `avs " + args.at(0) + "`: " + std::strerror(rc));
  }
}

AvsChild::~AvsChild() {
  terminate();
  (void)wait();
}

bool AvsChild::running() const {
  return pid_ > 0 && waitpid(pid_, nullptr, WNOHANG) == 0;
}

void AvsChild::terminate() {
  if (pid_ > 0) kill(pid_, SIGTERM);
}

int AvsChild::wait() {
  if (pid_ <= 0) return status_;
  int st = 0;
  while (waitpid(pid_, &st, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
  status_ = st;
  return st;
}

pid_t container_pid(pid_t launcher, const std::string& name) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/proc", ec)) {
    const std::string pid_text = entry.path().filename().string();
    if (pid_text.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(entry.path() / "stat");
    std::string line;
    if (!std::getline(stat, line)) continue;
    // "pid (comm) state ppid ...": the command may hold spaces and parentheses.
    const auto close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 1));
    std::string state;
    pid_t ppid = 0;
    rest >> state >> ppid;
    if (ppid != launcher || state == "Z") continue;
    std::ifstream cmdline(entry.path() / "cmdline");
    std::vector<std::string> words;
    for (std::string w; std::getline(cmdline, w, '\0');) words.push_back(w);
    for (std::size_t i = 0; i + 1 < words.size(); ++i) {
      if (words[i] == "--name" && words[i + 1] == name) return std::atoi(pid_text.c_str());
    }
  }
  return -1;
}

}  // namespace avs::cli
