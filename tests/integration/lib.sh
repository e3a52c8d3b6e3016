# Helpers for the integration scripts: fail with a message, read a YAML report value.
fail() { echo "FAIL: $*" >&2; exit 1; }
value() { grep "^$2:" "$1" | awk '{print $2}'; }
