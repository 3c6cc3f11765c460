#!/bin/bash
# f.sh NAME SIZE [reconstruct args]: fountain depth run at SIZE + eval
NAME=$1; SIZE=$2; shift 2
D=/work/shared/datasets/strecha_fountain-P11
B=/work/main/devel/lib/wild_mvs
O=/tmp/s21/$NAME
rm -rf $O; mkdir -p $O
/usr/bin/time -v $B/wild_mvs reconstruct $D $O --model $D/colmap_sift_gt --images $D/images --max-image-size $SIZE --stages depth --threads 2 "$@" > $O/log.txt 2> $O/time.txt
$B/wild_mvs eval depth --est $O --dataset $D --rel-thresholds 0.005,0.01,0.05 > $O/eval.txt 2>&1
echo "== $NAME"; grep -E "User time|System time" $O/time.txt | tr '\n' ' '; echo
tail -4 $O/eval.txt
