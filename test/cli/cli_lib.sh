# Helpers for the CLI tests (sourced; not a test itself).
# Usage in a test: source "$(dirname "$0")/cli_lib.sh" "$@"
# Sets WILD_MVS (the binary), SHARED (../shared or ""), SRC (source tree),
# TMP (a fresh folder removed at exit).
set -u
WILD_MVS="$1"
SHARED="${2:-}"
SRC="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
TMP="$(mktemp -d "${TMPDIR:-/tmp}/wild_mvs_cli_test.XXXXXX")"
trap 'chmod -R u+w "$TMP" 2>/dev/null; rm -rf "$TMP"' EXIT
FAILURES=0

fail() { echo "FAIL: $*" >&2; FAILURES=$((FAILURES + 1)); }
pass() { echo "ok: $*"; }

# expect_fail EXPECTED_STATUS PATTERN -- command...: the command must exit
# with EXPECTED_STATUS (or any non-zero status when "nz") and print one
# line to stderr starting with "wild_mvs" that matches PATTERN (grep -E).
expect_fail() {
  local want="$1" pattern="$2"
  shift 3
  local out rc=0
  out="$("$@" 2>&1 >/dev/null)" || rc=$?
  if [ "$rc" -eq 0 ]; then
    fail "expected failure, got success: $*"
    return
  fi
  if [ "$rc" -ge 128 ]; then
    fail "crashed with signal $((rc - 128)): $*"
    return
  fi
  if [ "$want" != nz ] && [ "$rc" -ne "$want" ]; then
    fail "exit status $rc (want $want): $* -- stderr: $out"
    return
  fi
  if ! grep -qE -- "$pattern" <<<"$out"; then
    fail "message does not match /$pattern/: $* -- stderr: $out"
    return
  fi
  pass "$(head -c 160 <<<"$out" | head -n1)"
}

# expect_ok command...: must exit 0; stdout+stderr saved in $TMP/last.log.
expect_ok() {
  local rc=0
  "$@" >"$TMP/last.log" 2>&1 || rc=$?
  if [ "$rc" -ne 0 ]; then
    fail "exit status $rc: $*"
    sed 's/^/    /' "$TMP/last.log" | tail -n 30 >&2
    return 1
  fi
  pass "$*"
}

finish() {
  if [ "$FAILURES" -ne 0 ]; then
    echo "$FAILURES check(s) failed" >&2
    exit 1
  fi
  echo "all checks passed"
}
