#!/bin/bash
# full.sh NAME [reconstruct args]: fountain depth run + eval
NAME=$1; shift
D=/work/shared/datasets/strecha_fountain-P11
B=/work/main/devel/lib/wild_mvs
O=/tmp/s20/$NAME
rm -rf $O; mkdir -p $O
/usr/bin/time -v $B/wild_mvs reconstruct $D $O --model $D/colmap_sift_gt --images $D/images --max-image-size 1536 --stages depth --threads 2 "$@" > $O/log.txt 2> $O/time.txt
$B/wild_mvs eval depth --est $O --dataset $D --rel-thresholds 0.005,0.01,0.05 > $O/eval.txt 2>&1
grep -E "User time|System time|Maximum resident" $O/time.txt
tail -5 $O/eval.txt
