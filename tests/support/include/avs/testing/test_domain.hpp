// DDS domains and TCP ports for tests, allocated instead of hand-numbered: CTest runs tests in
// parallel (every GoogleTest case is a process of its own), and two tests on one DDS domain hear
// each other's samples and break each other's lockstep. A test process leases the first free
// domain of kFirstTestDomain..kLastTestDomain by holding a lock file on it (flock) for as long as
// it lives; tests/support/test_domain.sh does the same for the CTest scripts with the same files.
// `avs demo`/`avs experiments` pick their private domains above this range (200-231).
#pragma once

namespace avs::testing {

inline constexpr int kFirstTestDomain = 100;
inline constexpr int kLastTestDomain = 199;

/// This process's DDS domain: leased on the first call, held until the process exits. Throws
/// std::runtime_error when every domain of the range is held.
int test_domain();

/// A TCP port of this process's own (Modbus servers of simulated amplifiers): 20000 +
/// 10 x test_domain() + index, index in [0, 9].
int test_tcp_port(int index = 0);

}  // namespace avs::testing
