# Filter rules scored over the per-sample features of feat.py (fountain-P11:
# GT pixels 15,062,954). Usage: /usr/bin/python3 rules.py FEATURES.npz
import sys
import numpy as np

d = dict(np.load(sys.argv[1]))
GT = 15062954
g, z = d['gt'], d['z']
hasgt = g > 0
ok = hasgt & (np.abs(z - g) < 0.01 * g)


def rep(name, keep):
    n = keep.sum()
    cov = (keep & hasgt).sum() / GT
    okk = (keep & ok).sum()
    print(f'{name:60s} cov {cov:.4f} corr {okk/GT:.4f} '
          f'w1 {okk/max(1, (keep & hasgt).sum()):.4f} bg {(keep & ~hasgt).sum()/n:.4f}')


c0, c1, f1, f5, conf = d['ncon'], d['ncon1'], d['nfree'], d['nfree2'], d['conf']
rep('all raw samples', np.ones(len(z), bool))
rep('exact pixel, >= 1 confirmation (d637482 default)', c0 >= 1)
rep('3x3, >= 1', c1 >= 1)
rep('3x3, >= 2', c1 >= 2)
# confirmations c against violations f (at 1 % and 5 %): keep f <= a c + b
for cn, c in (('exact', c0), ('3x3', c1)):
    for fn, f in (('viol1%', f1), ('viol5%', f5)):
        for a, b in ((1, 0), (1, -1), (0.5, 0), (2, 0), (1, 1), (0.5, 1)):
            rep(f'{cn} >= 1 & {fn} <= {a} c + {b}', (c >= 1) & (f <= a * c + b))
base = (c1 >= 1) & (f1 <= c1)
for cc in (0.8, 0.85, 0.9):
    rep(f'3x3 & viol1% <= c & (c >= 2 | conf >= {cc})',
        base & ((c1 >= 2) | (conf >= cc)))
for k in range(6):
    m = c1 == k
    print(f'3x3 confirmations {k}: {m.sum()/GT:.4f} of GT, '
          f'{(m & ok).sum()/max(1, m.sum()):.3f} correct, '
          f'{(m & ~hasgt).sum()/max(1, m.sum()):.3f} background')
