import numpy as np
def read_pfm(p):
    with open(p,'rb') as f:
        h=f.readline().strip(); w,hh=map(int,f.readline().split()); s=float(f.readline())
        d=np.frombuffer(f.read(),dtype='<f4' if s<0 else '>f4')
        c=3 if h==b'PF' else 1
        return np.flipud(d.reshape(hh,w,c) if c==3 else d.reshape(hh,w))
