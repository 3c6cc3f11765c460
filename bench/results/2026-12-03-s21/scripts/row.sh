#!/bin/bash
for n in "$@"; do
E=/tmp/s21/$n/eval.txt
python3 - "$n" "$E" /tmp/s21/$n/time.txt <<'P'
import sys,re
n,e,t=sys.argv[1:4]; s=open(e).read().split("all 11 views")[-1]
g=lambda p: float(re.search(p,s).group(1))
gt,est,both,bg=[int(x) for x in re.search(r"ground truth (\d+), estimated (\d+), both (\d+), estimated without ground truth (\d+)",s).groups()]
w05=g(r"within 0.50 % relative: ([\d.]+) %"); w1=g(r"within 1.00 % relative: ([\d.]+) %"); w1g=g(r"within 1.00 % relative: [\d.]+ % of estimated, ([\d.]+) %"); w5=g(r"within 5.00 % relative: ([\d.]+) %")
T=open(t).read(); cpu=float(re.search(r"User time \(seconds\): ([\d.]+)",T).group(1))+float(re.search(r"System time \(seconds\): ([\d.]+)",T).group(1))
print(f"{n}\tcov {both/gt*100:.2f}\tw0.5 {w05:.2f}\tw1 {w1:.2f}\tGTw1 {w1g:.2f}\toff5 {100-w5:.2f}\tbg {bg/est*100:.2f}\tcpu {cpu:.1f}\tcorrect {est*w1/100:.0f}")
P
done
