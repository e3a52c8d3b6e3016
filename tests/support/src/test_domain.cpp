#include "avs/testing/test_domain.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace avs::testing {
namespace {

/// Locks `dir/<id>.lock` for the first free id; the descriptor stays open (and the lock held)
/// until the process exits. O_CLOEXEC: a child program gets the domain through AVS_DOMAIN_ID,
/// not the lock, so a leaked child cannot keep a domain.
int lease_domain() {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "avs-test-domains";
  std::filesystem::create_directories(dir);
  for (int id = kFirstTestDomain; id <= kLastTestDomain; ++id) {
    const std::string file = (dir / (std::to_string(id) + ".lock")).string();
    const int fd = open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) continue;
    if (flock(fd, LOCK_EX | LOCK_NB) == 0) return id;  // fd deliberately kept open
    close(fd);
  }
  throw std::runtime_error("no free test DDS domain in " + std::to_string(kFirstTestDomain) +
                           "-" + std::to_string(kLastTestDomain) + " (lock files in " +
                           dir.string() + ")");
}

}  // namespace

int test_domain() {
  static const int domain = lease_domain();
  return domain;
}

int test_tcp_port(int index) {
  if (index < 0 || index > 9) throw std::invalid_argument("test_tcp_port: index in [0, 9]");
  return 20000 + 10 * test_domain() + index;
}

}  // namespace avs::testing
