# Helpers for the integration scripts: fail with a message, read a YAML report value. Each
# script runs on a DDS domain of its own (tests/support/test_domain.sh exports AVS_DOMAIN_ID).
. "$(dirname "${BASH_SOURCE[0]}")/../support/test_domain.sh"
fail() { echo "FAIL: $*" >&2; exit 1; }
value() { grep "^$2:" "$1" | awk '{print $2}'; }
