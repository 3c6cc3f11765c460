#!/usr/bin/env python3
# Histogram of the mean NCC (2 * confidence - 1) of estimates on one-view
# occluder pixels, correct ones and other wrong ones (> 5 %).
# usage: occluder_ncc.py RUN CLUTTER_SCENE CONSTANT_SCENE SUB (SUB = raw or .)
import sys, os
exec(open(os.path.join(os.path.dirname(os.path.abspath(__file__)), 'occluder_breakdown.py')).read().split('run, cs, ks =')[0])
from collections import Counter
run, cs, ks, sub = sys.argv[1:5]
H = {'occ': Counter(), 'good': Counter(), 'bad': Counter()}
for fn in sorted(os.listdir(os.path.join(cs, 'gt_depth'))):
    w, h, g = pfm(os.path.join(cs, 'gt_depth', fn))
    _, _, k = pfm(os.path.join(ks, 'gt_depth', fn))
    _, _, e = pfm(os.path.join(run, sub, 'depth', fn))
    _, _, cf = pfm(os.path.join(run, sub, 'confidence', fn))
    for r in range(h):
        for c in range(w):
            z = e[r][c]
            if not z > 0: continue
            gt = g[r][c]
            if not gt > 0: continue
            ncc = 2 * cf[r][c] - 1
            b = min(19, max(0, int((ncc - 0.0) * 20)))  # 0.05 bins from 0
            occ = k[r][c] <= 0 or gt < 0.95 * k[r][c]
            bad = abs(z - gt) > 0.05 * gt
            H['occ' if occ else ('bad' if bad else 'good')][b] += 1
for key in H:
    tot = sum(H[key].values())
    cum = 0
    print(key, tot)
    print('  ' + ' '.join('%.2f:%.3f' % (b / 20.0, H[key][b] / max(1, tot)) for b in range(20)))
