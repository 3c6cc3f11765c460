import numpy as np, glob, os, sys
sys.path.insert(0,'/tmp/s21'); from pfm import read_pfm
import cv2
A,B=sys.argv[1],sys.argv[2]
tot={}
for f in sorted(glob.glob(A+'/depth/*.pfm')):
    n=os.path.basename(f); a=read_pfm(f); b=read_pfm(B+'/depth/'+n)
    va=np.isfinite(a)&(a>0); vb=np.isfinite(b)&(b>0)
    img=cv2.imread('/work/main/data/templeSparseRing/'+n.replace('.pfm','.png'),0)
    img=cv2.resize(img,(a.shape[1],a.shape[0]),interpolation=cv2.INTER_AREA)
    bg=(img<30).astype(np.uint8)
    dist=cv2.distanceTransform(1-bg,cv2.DIST_L2,3)
    for k,m in [('onlyB',vb&~va),('onlyA',va&~vb),('both',va&vb)]:
        for lo,hi in [(0,3),(3,6),(6,1e9)]:
            tot[(k,lo)]=tot.get((k,lo),0)+int((m&(dist>lo)&(dist<=hi)).sum())
        tot[(k,'bg')]=tot.get((k,'bg'),0)+int((m&(bg>0)).sum())
    both=va&vb; rel=np.abs(a[both]-b[both])/b[both]
    tot['agree']=tot.get('agree',0)+int((rel<0.01).sum()); tot['bothn']=tot.get('bothn',0)+int(both.sum())
for k,v in tot.items(): print(k,v)
