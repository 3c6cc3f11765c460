#!/usr/bin/env bash
# The shipped files carry no development history: no commit hashes, issue
# numbers, work periods (dates, session tags, worktree names), development
# machines or workstation paths. Usage: test_no_history.sh SOURCE_DIR
# Scans the tracked files under src include test docs bench scripts config
# launch cmake, README.md and CMakeLists.txt (git ls-files; every file
# there without git); prints file:line of every hit and exits 1 if any.
# docs/RESULTS.md and docs/ABLATION.md are exempt: they are generated and
# name the machine and the commit they were measured on. First checks
# itself on planted lines.
set -uo pipefail
ROOT="${1:?usage: test_no_history.sh SOURCE_DIR}"

# In every text file. Hashes: 7-40 hex digits with a letter and a digit,
# not part of a number or an identifier (0x1f2e3d4c, 0.0031308f pass).
ALL='(?<![\w.])(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}(?![\w.])'
ALL+='|\bissues? #?[0-9]+|\bwt-[a-z]|/home/|/work/|\b(EPYC|Xeon) VM\b'
ALL+='|\bagents\b|\b20[0-9]{2}-[01][0-9]-[0-3][0-9]\b'
ALL+='|\b(third|fourth|fifth|sixth) session\b|\bthis session\x27s\b|\bsession of 20'
# In prose and scripts only (code may have variables called s12).
PROSE='\bs[0-9]{2}b?\b'

scan() {  # FILE...: prints FILE:LINE: TEXT for every hit (one grep per pattern)
  local f prose=()
  [ $# -gt 0 ] || return 0
  grep -H -n -I -i -P -- "$ALL" "$@" 2>/dev/null
  for f in "$@"; do
    case "$f" in
      *.md | *.txt | *.sh | *.py | *.yaml | *.launch | *.test | *.cmake | *.xml | *CMakeLists.txt)
        prose+=("$f") ;;
    esac
  done
  [ ${#prose[@]} -eq 0 ] || grep -H -n -I -P -- "$PROSE" "${prose[@]}" 2>/dev/null
  return 0
}

# Self-check: planted history is found, legitimate code is not.
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# (Assembled from pieces so that this file itself names no history.)
printf '%s\n' 'fixed in c5f2''fbe' 'see iss''ue 12' 'ran on the AMD EP''YC VM' \
  'results of 2026-''12-02' 'wt-''speed branch' 'the third sess''ion' \
  'other ag''ents builds' 'cp /ho''me/user/x' >"$tmp/bad.md"
printf '%s\n' 'run s''20 temple' >"$tmp/tag.sh"
printf '%s\n' 'uint32_t h = 0x9e3779b9;' 'if (v <= 0.0031308f) return v;' \
  'FusionStats s8, s32;' 'a new session starts' 'sha256 of the file' >"$tmp/good.cpp"
planted=$(scan "$tmp/bad.md" "$tmp/tag.sh" | wc -l)
if [ "$planted" -ne 9 ]; then
  echo "test_no_history: the patterns found $planted of 9 planted lines:" >&2
  scan "$tmp/bad.md" "$tmp/tag.sh" >&2
  exit 1
fi
if [ -n "$(scan "$tmp/good.cpp")" ]; then
  echo "test_no_history: the patterns trip on legitimate code:" >&2
  scan "$tmp/good.cpp" >&2
  exit 1
fi

cd "$ROOT" || exit 1
dirs=(src include test docs bench scripts config launch cmake README.md CMakeLists.txt)
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files -- "${dirs[@]}")
else
  mapfile -t files < <(find "${dirs[@]}" -type f 2>/dev/null)
fi
keep=()
for f in "${files[@]}"; do
  case "$f" in
    docs/RESULTS.md | docs/ABLATION.md | */SHA256SUMS | test/data/* | test/fuzz/corpus/* | test/repo/test_no_history.sh) ;;
    *) [ -f "$f" ] && keep+=("$f") ;;
  esac
done
hits=$(scan "${keep[@]}")
if [ -n "$hits" ]; then
  echo "Shipped files name development history (commit hashes, issue numbers," >&2
  echo "work periods, machines or workstation paths); move measurements to the" >&2
  echo "generated docs/RESULTS.md and say what, not when:" >&2
  echo "$hits" | cut -c1-200 >&2
  echo "($(echo "$hits" | wc -l) lines)" >&2
  exit 1
fi
echo "test_no_history: ${#keep[@]} shipped files, no development history"
