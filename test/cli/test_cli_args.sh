#!/usr/bin/env bash
# Command-line mistakes and bad config files give one clear message naming
# the option / file / line, a non-zero status, and no crash.
source "$(dirname "$0")/cli_lib.sh" "$@"

# Dispatcher.
expect_fail 2 "usage: wild_mvs" -- "$WILD_MVS"
expect_fail 2 "unknown command 'frobnicate'" -- "$WILD_MVS" frobnicate
expect_ok "$WILD_MVS" --help
grep -q reconstruct "$TMP/last.log" || fail "--help does not list reconstruct"

# Every command documents itself with --help and exits 0.
for cmd in info sparse reconstruct fuse mesh eval to-bag; do
  expect_ok "$WILD_MVS" "$cmd" --help
  grep -q "usage: wild_mvs $cmd" "$TMP/last.log" ||
    fail "$cmd --help has no usage line"
done

# Argument errors (exit 2, message names the option).
R=reconstruct
expect_fail 2 "^wild_mvs reconstruct: unknown option --bogus" -- \
  "$WILD_MVS" $R --bogus 1 A B
expect_fail 2 "^wild_mvs reconstruct: missing argument DATASET OUT" -- \
  "$WILD_MVS" $R
expect_fail 2 "^wild_mvs reconstruct: missing argument OUT" -- \
  "$WILD_MVS" $R somewhere
expect_fail 2 "unexpected argument 'C'" -- "$WILD_MVS" $R A B C
expect_fail 2 "option --threads needs a value" -- "$WILD_MVS" $R A B --threads
# Values are parsed by type; ranges are the options' Check() (its message).
expect_fail 1 "run.threads = -3 must be in \\[0, 4096\\]" -- \
  "$WILD_MVS" $R A B --threads -3
expect_fail 1 "mpgc.window = 4 must be odd and in \\[3, 9\\]" -- \
  "$WILD_MVS" $R A B --mvs.mpgc.window 4
expect_fail 1 "mpgc.drop_ncc = 2 must be in \\[-1, 1\\]" -- \
  "$WILD_MVS" $R A B --mvs.mpgc.drop_ncc=2
expect_fail 2 "option --threads: run.threads: 'many' is not an integer" -- \
  "$WILD_MVS" $R A B --threads many
expect_fail 2 "option --image.cache_mb: 'nan' is not a finite number" -- \
  "$WILD_MVS" $R A B --image.cache_mb nan
expect_fail 2 "option --ablation.linearize: 'maybe' is not a boolean" -- \
  "$WILD_MVS" $R A B --ablation.linearize=maybe
expect_fail nz "run.stages: unknown stage 'paint'" -- \
  "$WILD_MVS" $R A B --stages depth,paint
expect_fail 2 "unknown option --image.cache" -- \
  "$WILD_MVS" $R A B --image.cache 3

# Config files: errors name the file, the line and the key.
CFG="$TMP/bad.yaml"
printf 'run:\n  threads: 2\nimage:\n  cache_m: 10\n' >"$CFG"
expect_fail 1 "bad.yaml line 4: unknown option 'image.cache_m'.*image.cache_mb" \
  -- "$WILD_MVS" $R --config "$CFG" A B
printf 'image:\n  cache_mb: 10\n  max_image_size: -5\n' >"$CFG"
expect_fail 1 "image.max_image_size = -5 must be >= 0" \
  -- "$WILD_MVS" $R --config "$CFG" A B
printf 'run:\n  threads: [1, 2]\n' >"$CFG"
expect_fail 1 "bad.yaml line 2: value of 'run.threads' must be a single value" \
  -- "$WILD_MVS" $R --config "$CFG" A B
printf 'run:\n  threads: 1\n  threads: 2\n' >"$CFG"
expect_fail 1 "bad.yaml line 3: duplicate key 'run.threads'" \
  -- "$WILD_MVS" $R --config "$CFG" A B
printf 'run: {threads: 1\n' >"$CFG"
expect_fail 1 "bad.yaml line [0-9]+: YAML syntax error" \
  -- "$WILD_MVS" $R --config "$CFG" A B
printf 'run: 3\n' >"$CFG"
expect_fail 1 "bad.yaml line 1: 'run' is a section" \
  -- "$WILD_MVS" $R --config "$CFG" A B
printf -- '- a\n- b\n' >"$CFG"
expect_fail 1 "bad.yaml line 1: the config must be a map" \
  -- "$WILD_MVS" $R --config "$CFG" A B
expect_fail 1 "missing.yaml: cannot open config file" \
  -- "$WILD_MVS" $R --config "$TMP/missing.yaml" A B

# Precedence: defaults < config < flags, shown by --dump-config.
printf 'run:\n  threads: 3\n  stages: depth\n' >"$TMP/good.yaml"
expect_ok "$WILD_MVS" $R --config "$TMP/good.yaml" --threads 5 --dump-config
grep -q "^  threads: 5$" "$TMP/last.log" || fail "flag did not override config"
grep -q '^  stages: "depth"$' "$TMP/last.log" || fail "config value not used"

# The shipped default config equals the defaults, and loads.
expect_ok "$WILD_MVS" $R --dump-config
# (The file adds a header comment; test/ros/test_config_files.sh compares it
# whole with what wild_mvs_write_config writes.)
if ! diff <(grep -Ev '^ *(#|$)' "$TMP/last.log") \
          <(grep -Ev '^ *(#|$)' "$SRC/config/reconstruct.yaml"); then
  fail "config/reconstruct.yaml differs from 'wild_mvs reconstruct --dump-config'"
fi
expect_ok "$WILD_MVS" $R --config "$SRC/config/reconstruct.yaml" --dump-config

# A dumped config reads back to the same values (round trip).
"$WILD_MVS" $R --threads 7 --image.cache_mb 12.5 --dump-config >"$TMP/rt.yaml"
expect_ok "$WILD_MVS" $R --config "$TMP/rt.yaml" --dump-config
diff -q "$TMP/rt.yaml" "$TMP/last.log" >/dev/null ||
  fail "dumped config does not round-trip"

# Every part of the method beyond the paper is a switch of the command line
# (bench/run_ablation.sh turns each off) and --preset paper turns it off.
for sw in photometric_offset consistency planar_prior explain_test \
  bilateral_window coarse_fill; do
  expect_ok "$WILD_MVS" $R --ablation.$sw false --dump-config
  grep -q "^  $sw: false" "$TMP/last.log" || fail "--ablation.$sw false not applied"
  expect_ok "$WILD_MVS" $R --dump-config
  grep -q "^  $sw: true" "$TMP/last.log" || fail "ablation.$sw is not on by default"
  expect_ok "$WILD_MVS" $R --preset paper --dump-config
  grep -q "^  $sw: false" "$TMP/last.log" || fail "--preset paper leaves $sw on"
done

# to-bag without the ROS build: a clear error.
if [ ! -x "$(dirname "$WILD_MVS")/wild_mvs_to_bag" ]; then
  expect_fail 1 "^wild_mvs to-bag: built without ROS" -- \
    "$WILD_MVS" to-bag A B.bag
fi
finish
