// AvsChild: this `avs` program run again as a child process (`avs container ...`,
// `avs launch ...`) on a given DDS configuration and domain, its output to a log file. What the
// benchmarks that need a second process share (`avs bench pipeline`, `avs bench faults`).
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace avs::cli {

class AvsChild {
 public:
  /// Starts `avs ARGS...` with CYCLONEDDS_URI = `cyclone_xml` and AVS_DOMAIN_ID = `domain`
  /// (the rest of the environment as ours), stdout and stderr to `log`. Throws runtime::Error
  /// naming `who` when it cannot start.
  AvsChild(const std::vector<std::string>& args, const std::string& cyclone_xml, int domain,
           const std::filesystem::path& log, const std::string& who);
  AvsChild(const AvsChild&) = delete;
  AvsChild& operator=(const AvsChild&) = delete;
  /// SIGTERM and wait, when still running.
  ~AvsChild();

  pid_t pid() const { return pid_; }
  /// Not exited yet.
  bool running() const;
  /// Sends SIGTERM (it stops cleanly: containers write their reports).
  void terminate();
  /// Waits for the exit; returns the waitpid status (that of the earlier wait when waited).
  int wait();

 private:
  pid_t pid_ = -1;
  int status_ = 0;
};

/// The pid of `launcher`'s child running container `name` (`avs launch` runs each as
/// `avs container FILE --name NAME`), or -1 when there is none (dead, or being restarted).
pid_t container_pid(pid_t launcher, const std::string& name);

}  // namespace avs::cli
