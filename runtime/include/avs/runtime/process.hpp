// For a child process the graph starts (a container of `avs launch`, iceoryx's RouDi): it must
// not outlive its launcher. A launcher killed with SIGKILL cannot stop its children, so each
// child asks the kernel for SIGTERM when its parent goes (issue 20 section 2: three containers
// kept publishing after their launcher was killed, and a relaunch failed on the used port).
#pragma once

#include <sys/prctl.h>
#include <unistd.h>

#include <csignal>

namespace avs::runtime {

/// Call in the child between fork() and exec(), with the parent's pid taken before fork().
/// Async-signal-safe. If the parent is already gone (it died before the call), exits at once.
/// The death signal survives exec (not set-uid programs) and is sent when the thread that
/// forked exits: launchers fork from their main thread.
inline void die_with_parent(pid_t parent) {
  prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (getppid() != parent) _exit(1);
}

}  // namespace avs::runtime
