#!/bin/bash
# Interleaved A/B on temple: ref (16f8844) vs new (wt-speed HEAD binary), AVX3 and AVX2.
cd /work/wt-speed
for round in 1 2; do
  for simd in AVX3 AVX2; do
    for which in ref new; do
      if [ $which = ref ]; then bd=/tmp/ref-src/build; else bd=/work/wt-speed/build-bench; fi
      WILD_MVS_SIMD_TARGET=$simd BUILD_DIR=$bd nice -n 5 bash bench/run_bench.sh --only temple --runs 1 --skip-build \
        --results bench/results/2026-12-02-wt-speed-ab/$which-$simd-round$round 2>&1 | grep '^temple *wild_mvs' | sed "s/^/$which $simd round$round /"
    done
  done
done
