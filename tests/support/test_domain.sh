# Sourced by the CTest scripts: exports AVS_DOMAIN_ID, a DDS domain this test holds alone, and
# AVS_TEST_PORT, a TCP port base of its own (20000 + 10 x domain, as test_tcp_port() in
# include/avs/testing/test_domain.hpp, whose lock files these are). The lock is held by a file
# descriptor of this shell until the script (and the children that inherit it) exits.
avs_lease_test_domain() {
  local dir=${TMPDIR:-/tmp}/avs-test-domains id
  mkdir -p "$dir"
  for ((id = 100; id <= 199; id++)); do
    exec {AVS_DOMAIN_LOCK_FD}>>"$dir/$id.lock"
    if flock -n "$AVS_DOMAIN_LOCK_FD"; then
      export AVS_DOMAIN_ID=$id AVS_TEST_PORT=$((20000 + 10 * id))
      return 0
    fi
    exec {AVS_DOMAIN_LOCK_FD}>&-
  done
  echo "no free test DDS domain in 100-199 (lock files in $dir)" >&2
  return 1
}
avs_lease_test_domain
