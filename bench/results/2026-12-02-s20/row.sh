#!/bin/bash
# row.sh NAME: one table row
r=/tmp/s20/$1
cpu=$(grep -E "User time|System time" $r/time.txt | awk '{s+=$NF} END {printf "%.1f", s}')
rss=$(grep "Maximum resident" $r/time.txt | awk '{printf "%.0f", $NF/1024}')
python3 - "$r/eval.txt" "$cpu" "$rss" "$1" <<'PY'
import re,sys
t=open(sys.argv[1]).read()
m=re.search(r"pixels: ground truth (\d+), estimated (\d+), both (\d+), estimated without ground truth (\d+)",t)
gt,est,both,nogt=map(int,m.groups())
c=re.search(r"completeness: ([\d.]+) %",t).group(1)
w05=re.search(r"within 0.50 % relative: ([\d.]+) % of estimated",t).group(1)
w1=re.search(r"within 1.00 % relative: ([\d.]+) % of estimated, ([\d.]+) % of ground truth",t)
w5=re.search(r"within 5.00 % relative: ([\d.]+) % of estimated",t).group(1)
med=re.search(r"median abs error: ([\d.]+)",t).group(1)
print(f"| {sys.argv[4]} | {c} % | {w05} % | {w1.group(1)} % | {100-float(w5):.2f} % | {w1.group(2)} % | {100*nogt/est:.2f} % | {float(med)*1000:.1f} mm | {sys.argv[2]} | {sys.argv[3]} MB |")
PY
