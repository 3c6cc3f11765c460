# background.py GT_DIR EST_DIR: fountain's estimates without ground truth,
# per view, by distance (px) to the nearest GT pixel: <= 2, 2-10, 10-50, > 50.
import numpy as np, glob, os, sys, cv2
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__))); from pfm import read_pfm
G, D = sys.argv[1], sys.argv[2]
T = [0] * 4; N = 0
for f in sorted(glob.glob(G + '/*.pfm')):
    n = os.path.basename(f); g = read_pfm(f); d = read_pfm(D + '/depth/' + n)
    gv = (np.isfinite(g) & (g > 0)).astype(np.uint8); dv = np.isfinite(d) & (d > 0)
    bg = dv & (gv == 0); N += dv.sum()
    dist = cv2.distanceTransform(1 - gv, cv2.DIST_L2, 3)
    c = [(bg & (dist <= 2)).sum(), (bg & (dist > 2) & (dist <= 10)).sum(),
         (bg & (dist > 10) & (dist <= 50)).sum(), (bg & (dist > 50)).sum()]
    T = [a + b for a, b in zip(T, c)]
    print(n, bg.sum(), c, f"{bg.sum() / dv.sum() * 100:.2f}%")
print('all', sum(T), [f"{t / N * 100:.2f}%" for t in T])
