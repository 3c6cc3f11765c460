#!/usr/bin/env bash
# Sourced by bench/run_all.sh and bench/run_ablation.sh (not run): the lines
# (key, tab, value) of a run's meta.tsv that say where and on which code the
# run was made.
#   run_meta_machine        cpu, cores, memory, kernel
#   run_meta_code ROOT      commit (noting uncommitted changes in src,
#                           include or CMakeLists.txt) and code: a hash of
#                           those trees as built, equal for two commits that
#                           differ only in docs, scripts or tests
#   run_meta_now            date (UTC) and load (the load average now)

run_meta_machine() {
  printf 'cpu\t%s\n' "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')"
  printf 'cores\t%s\n' "$(nproc)"
  printf 'memory\t%s\n' "$(awk '/MemTotal/ {printf "%.0f GB", $2 / 1048576}' /proc/meminfo)"
  printf 'kernel\t%s\n' "$(uname -r)"
}

run_meta_code() {
  local root="$1" commit code changes
  commit=$(git -C "$root" rev-parse --short=12 HEAD 2>/dev/null || echo unknown)
  code=$(git -C "$root" ls-tree HEAD src include CMakeLists.txt 2>/dev/null |
    git hash-object --stdin 2>/dev/null | cut -c1-12)
  changes=$(git -C "$root" status --porcelain --untracked-files=no -- src include \
    CMakeLists.txt 2>/dev/null)
  if [ -n "$changes" ]; then
    commit="$commit (with uncommitted changes in src/include)"
    code="$code+changes"
  fi
  printf 'commit\t%s\n' "$commit"
  printf 'code\t%s\n' "${code:-unknown}"
}

run_meta_now() {
  printf 'date\t%s\n' "$(date -u '+%Y-%m-%d %H:%M UTC')"
  printf 'load\tload average %s at the end (other jobs share the machine; CPU-s stay comparable, wall time would not)\n' \
    "$(cut -d' ' -f1-3 /proc/loadavg)"
}
