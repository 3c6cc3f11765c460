# Per raw sample features vs GT correctness (fountain). Usage: feat.py RAWDIR GTDIR OUT.npz
import sys, os, numpy as np
def pfm(p):
    with open(p,'rb') as f:
        h=f.readline().strip(); w,hh=map(int,f.readline().split()); s=float(f.readline())
        c=3 if h==b'PF' else 1
        a=np.frombuffer(f.read(),dtype='<f4' if s<0 else '>f4').reshape(hh,w,c) if c==3 else np.frombuffer(f.read(),dtype='<f4' if s<0 else '>f4').reshape(hh,w)
    return np.flipud(a).copy()
def cam(p):
    L=[l for l in open(p).read().split('\n') if l and not l.startswith('#')]
    w,h=map(int,L[0].split()); fx,fy,cx,cy=map(float,L[1].split())
    R=np.array([list(map(float,L[i].split())) for i in (2,3,4)]); t=np.array(list(map(float,L[5].split())))
    n=int(L[6]); nb=[x.rsplit('.',1)[0] for x in L[7:7+n]]
    return dict(w=w,h=h,fx=fx,fy=fy,cx=cx,cy=cy,R=R,t=t,nb=nb)
raw,gtd,out=sys.argv[1:4]
stems=sorted(f[:-4] for f in os.listdir(raw+'/depth'))
C={s:cam(f'{raw}/cameras/{s}.txt') for s in stems}
Dm={s:pfm(f'{raw}/depth/{s}.pfm') for s in stems}
def back(c,x,y,z):
    Xc=np.stack([(x+0.5-c['cx'])/c['fx']*z,(y+0.5-c['cy'])/c['fy']*z,z],-1)
    return (Xc-c['t'])@c['R']   # R^T (Xc - t)
def proj(c,X):
    Xc=X@c['R'].T+c['t']; z=Xc[:,2]
    with np.errstate(divide='ignore',invalid='ignore'):
        u=Xc[:,0]/z*c['fx']+c['cx']; v=Xc[:,1]/z*c['fy']+c['cy']
    return u,v,z
res={k:[] for k in ['view','x','y','z','gt','conf','ncon','ncon1','nhas','nfree','nocc','ninside','nfree2']}
for s in stems:
    c=C[s]; D=Dm[s]; G=pfm(f'{gtd}/{s}.pfm'); conf=pfm(f'{raw}/confidence/{s}.pfm')
    y,x=np.nonzero(D>0); z=D[y,x].astype(np.float64)
    X=back(c,x,y,z)
    ncon=np.zeros(len(z),np.int16); ncon1=ncon.copy(); nhas=ncon.copy(); nfree=ncon.copy(); nocc=ncon.copy(); ninside=ncon.copy(); nfree2=ncon.copy()
    for nbs in c['nb']:
        if nbs not in C: continue
        b=C[nbs]; B=Dm[nbs]
        u,v,zx=proj(b,X)
        qx=np.floor(u).astype(np.int64); qy=np.floor(v).astype(np.int64)
        ins=(zx>0)&(qx>=0)&(qy>=0)&(qx<b['w'])&(qy<b['h'])
        ninside+=ins
        best_ok=np.zeros(len(z),bool); any_has=np.zeros(len(z),bool)
        zq=np.zeros(len(z)); 
        for dy in (-1,0,1):
            for dx in (-1,0,1):
                xx=qx+dx; yy=qy+dy
                ok=ins&(xx>=0)&(yy>=0)&(xx<b['w'])&(yy<b['h'])
                zv=np.zeros(len(z)); zv[ok]=B[yy[ok],xx[ok]]
                has=zv>0
                Y=back(b,xx,yy,np.where(has,zv,1.0))
                pu,pv,zb=proj(c,Y)
                rt=has&(np.hypot(pu-(x+0.5),pv-(y+0.5))<=1.0)&(np.abs(zb-z)<=0.01*z)
                if dx==0 and dy==0:
                    ncon+=rt; nhas+=has; zq=zv
                best_ok|=rt
        ncon1+=best_ok
        h=zq>0
        nfree+=h&(zq>zx*1.01)
        nfree2+=h&(zq>zx*1.05)
        nocc+=h&(zq<zx*0.99)
    gz=G[y,x]
    for k,vv in [('view',np.full(len(z),int(s))),('x',x),('y',y),('z',z),('gt',gz),('conf',conf[y,x]),('ncon',ncon),('ncon1',ncon1),('nhas',nhas),('nfree',nfree),('nocc',nocc),('ninside',ninside),('nfree2',nfree2)]:
        res[k].append(vv)
    print(s,len(z),flush=True)
np.savez(out,**{k:np.concatenate(v) for k,v in res.items()})
