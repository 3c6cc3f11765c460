#!/usr/bin/env python3
# (wt-clutter, 2026-12-02; docs/EVALUATION.md "One-view occluders")
# Where the clutter scene's gross errors are: on one-view occluder pixels
# (GT of clutter in front of GT of constant) or elsewhere; distance of the
# occluder errors from the silhouette. usage: clutter_analyze.py RUN CLUTTER_SCENE CONSTANT_SCENE [sub=depth]
import sys, os, array
from collections import Counter
def pfm(path):
    with open(path, 'rb') as f:
        data = f.read()
    parts = data.split(b'\n', 3)
    w, h = map(int, parts[1].split()); scale = float(parts[2])
    a = array.array('f'); a.frombytes(parts[3][:w*h*4])
    if scale > 0: a.byteswap()
    # rows bottom to top -> flip
    rows = [a[(h-1-r)*w:(h-r)*w] for r in range(h)]
    return w, h, rows
run, cs, ks = sys.argv[1:4]
sub = sys.argv[4] if len(sys.argv) > 4 else 'depth'
tot = Counter()
for fn in sorted(os.listdir(os.path.join(cs, 'gt_depth'))):
    stem = fn[:-4]
    w, h, g = pfm(os.path.join(cs, 'gt_depth', fn))
    _, _, k = pfm(os.path.join(ks, 'gt_depth', fn))
    p = os.path.join(run, sub, fn)
    if not os.path.exists(p): continue
    we, he, e = pfm(p)
    assert (we, he) == (w, h)
    occ = [[g[r][c] > 0 and (k[r][c] <= 0 or g[r][c] < 0.95 * k[r][c]) for c in range(w)] for r in range(h)]
    v = Counter()
    for r in range(h):
        for c in range(w):
            z = e[r][c]
            if not z > 0: continue
            v['est'] += 1
            gt = g[r][c]
            if not gt > 0: v['sky'] += 1; continue
            bad = abs(z - gt) > 0.05 * gt
            if occ[r][c]:
                v['occ_est'] += 1
                if bad:
                    v['occ_bad'] += 1
                    kb = k[r][c]
                    if kb > 0 and abs(z - kb) < 0.02 * kb: v['occ_bad_bg'] += 1
                    # distance to silhouette (chebyshev)
                    d = None
                    for rad in range(1, 9):
                        found = False
                        for rr in range(max(0, r-rad), min(h, r+rad+1)):
                            for cc in (c-rad, c+rad):
                                if 0 <= cc < w and not occ[rr][cc]: found = True
                        for cc in range(max(0, c-rad), min(w, c+rad+1)):
                            for rr in (r-rad, r+rad):
                                if 0 <= rr < h and not occ[rr][cc]: found = True
                        if found: d = rad; break
                    v['occ_bad_d%s' % (d if d is not None and d <= 4 else ('5-8' if d else '>8'))] += 1
            else:
                if bad: v['other_bad'] += 1
    v['occ_px'] = sum(sum(1 for x in row if x) for row in occ)
    print(stem, dict(sorted(v.items())))
    tot.update(v)
print('TOTAL', dict(sorted(tot.items())))
b = tot['occ_bad'] + tot['other_bad']
print('off>5%% of GT estimates: %.3f %% (occ %.3f %%, other %.3f %%)' % (100.0*b/(tot['est']-tot['sky']), 100.0*tot['occ_bad']/(tot['est']-tot['sky']), 100.0*tot['other_bad']/(tot['est']-tot['sky'])))
