# Eroding the nearer side of depth edges. Usage: edge.py OUT GTDIR
import numpy as np, sys
import os
exec(open(os.path.join(os.path.dirname(os.path.abspath(__file__)), 'feat.py')).read().split('raw,gtd,out=')[0])
run=sys.argv[1]
GT=15062954
tot={}
for r in [0,1,2,3]:
  for thr in [0.02,0.05]:
    tot[(r,thr)]=np.zeros(4)
for v in range(11):
    s=f'{v:04d}'; D=pfm(f'{run}/depth/{s}.pfm'); G=pfm(f'{sys.argv[2]}/{s}.pfm')
    h,w=D.shape
    for thr in [0.02,0.05]:
        # closer side of a depth jump: pixel p with a 4-neighbour q valid and D[q] > D[p]*(1+thr)
        fg=np.zeros((h,w),bool)
        for dy,dx in [(0,1),(0,-1),(1,0),(-1,0)]:
            q=np.zeros_like(D); 
            ys=slice(max(dy,0),h+min(dy,0)); yd=slice(max(-dy,0),h+min(-dy,0))
            xs=slice(max(dx,0),w+min(dx,0)); xd=slice(max(-dx,0),w+min(-dx,0))
            q[yd,xd]=D[ys,xs]
            fg|=(D>0)&(q>D*(1+thr))
        m=fg.copy()
        for r in [0,1,2,3]:
            if r>0:
                mm=m.copy()
                for dy,dx in [(0,1),(0,-1),(1,0),(-1,0)]:
                    ys=slice(max(dy,0),h+min(dy,0)); yd=slice(max(-dy,0),h+min(-dy,0))
                    xs=slice(max(dx,0),w+min(dx,0)); xd=slice(max(-dx,0),w+min(-dx,0))
                    mm[yd,xd]|=m[ys,xs]
                m=mm&(D>0)
            keep=(D>0)&~(m if r>0 else np.zeros_like(m))
            if r==0: keep=(D>0)&~fg
            hg=G>0
            ok=keep&hg&(np.abs(D-G)<0.01*G)
            tot[(r,thr)]+=[keep.sum(),(keep&hg).sum(),ok.sum(),(keep&~hg).sum()]
base=None
for k,t in tot.items():
    print(k, f'cov {t[1]/GT:.4f} corr {t[2]/GT:.4f} w1 {t[2]/t[1]:.4f} bg {t[3]/t[0]:.4f}')
