# edge_band.py GT_DIR EST_DIR: fraction within 1 % of the estimates near
# and away from the ground truth's depth discontinuities (a neighbour's GT
# depth differs by > 3 %), for bands of 1, 2, 3 and 5 px.
# GT_DIR: coverage_breakdown --dump-gt (GT at the working resolution).
import numpy as np, glob, os, sys, cv2
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__))); from pfm import read_pfm
G, D = sys.argv[1], sys.argv[2]
tot = {}
for f in sorted(glob.glob(G + '/*.pfm')):
    n = os.path.basename(f); g = read_pfm(f); d = read_pfm(D + '/depth/' + n)
    gv = np.isfinite(g) & (g > 0); gz = np.where(gv, g, 0)
    edge = np.zeros(g.shape, bool)
    for dy, dx in [(0, 1), (1, 0)]:
        a = gz[:g.shape[0]-dy, :g.shape[1]-dx]; b = gz[dy:, dx:]
        j = np.abs(a - b) > 0.03 * np.maximum(a, b)
        edge[:g.shape[0]-dy, :g.shape[1]-dx] |= j; edge[dy:, dx:] |= j
    m = gv & np.isfinite(d) & (d > 0)
    e = np.abs(d - gz) / np.where(gv, gz, 1)
    for r in [1, 2, 3, 5]:
        k = cv2.dilate(edge.astype(np.uint8), np.ones((2*r+1, 2*r+1), np.uint8)) > 0
        for name, sel in [(f'near{r}', m & k), (f'far{r}', m & ~k)]:
            t = tot.setdefault(name, [0, 0]); t[0] += sel.sum(); t[1] += (sel & (e < 0.01)).sum()
    t = tot.setdefault('all', [0, 0]); t[0] += m.sum(); t[1] += (m & (e < 0.01)).sum()
N = tot['all'][0]
for k, (a, b) in tot.items():
    print(k, a, f"{a/N:.4f} of estimates", f"w1 {b/a:.4f}", f"bad {(a-b)/N:.4f} of all")
