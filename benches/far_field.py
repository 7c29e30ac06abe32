# The comparison of benches/far_field.sh: a frame against one K times as wide and tall,
# averaged over K x K blocks in linear light, on the pixels the snake covers whole (every
# sub-pixel of the block off the background): CIEDE2000 and mean chroma (CIELAB, D65), per
# pixel and over 4 x 4 blocks of pixels.
import sys, numpy as np
from PIL import Image
def lin(a):
    a=a/255.0; return np.where(a<=0.04045,a/12.92,((a+0.055)/1.055)**2.4)
def lab(rgb):
    M=np.array([[0.4124,0.3576,0.1805],[0.2126,0.7152,0.0722],[0.0193,0.1192,0.9505]])
    t=(rgb@M.T)/np.array([0.95047,1.0,1.08883])
    f=np.where(t>0.008856,np.cbrt(t),7.787*t+16/116)
    return np.stack([116*f[...,1]-16,500*(f[...,0]-f[...,1]),200*(f[...,1]-f[...,2])],-1)
def de2000(l1,l2):
    L1,a1,b1=l1.T; L2,a2,b2=l2.T
    C1=np.hypot(a1,b1); C2=np.hypot(a2,b2); Cm=(C1+C2)/2
    G=0.5*(1-np.sqrt(Cm**7/(Cm**7+25**7)))
    a1p=(1+G)*a1; a2p=(1+G)*a2
    C1p=np.hypot(a1p,b1); C2p=np.hypot(a2p,b2)
    h1=np.degrees(np.arctan2(b1,a1p))%360; h2=np.degrees(np.arctan2(b2,a2p))%360
    dL=L2-L1; dC=C2p-C1p
    dh=h2-h1; dh=np.where(C1p*C2p==0,0,np.where(dh>180,dh-360,np.where(dh<-180,dh+360,dh)))
    dH=2*np.sqrt(C1p*C2p)*np.sin(np.radians(dh/2))
    Lm=(L1+L2)/2; Cmp=(C1p+C2p)/2
    hs=h1+h2; hm=np.where(C1p*C2p==0,hs,np.where(np.abs(h1-h2)<=180,hs/2,np.where(hs<360,(hs+360)/2,(hs-360)/2)))
    T=1-0.17*np.cos(np.radians(hm-30))+0.24*np.cos(np.radians(2*hm))+0.32*np.cos(np.radians(3*hm+6))-0.20*np.cos(np.radians(4*hm-63))
    dth=30*np.exp(-((hm-275)/25)**2); RC=2*np.sqrt(Cmp**7/(Cmp**7+25**7))
    SL=1+0.015*(Lm-50)**2/np.sqrt(20+(Lm-50)**2); SC=1+0.045*Cmp; SH=1+0.015*Cmp*T
    RT=-np.sin(np.radians(2*dth))*RC
    return np.sqrt((dL/SL)**2+(dC/SC)**2+(dH/SH)**2+RT*(dC/SC)*(dH/SH))
# Sharma, Wu & Dalal (2005) test pair 1: 2.0425.
assert abs(de2000(np.array([[50,2.6772,-79.7751]]),np.array([[50,0,-82.7485]]))[0]-2.0425)<1e-4
lo=lin(np.asarray(Image.open(sys.argv[1]).convert('RGB'),dtype=float))
hir=lin(np.asarray(Image.open(sys.argv[2]).convert('RGB'),dtype=float))
h,w,_=lo.shape; k=hir.shape[0]//h
covered=(np.abs(hir-hir[0,0]).sum(-1)>0.01).reshape(h,k,w,k).all(axis=(1,3))
hi=hir.reshape(h,k,w,k,3).mean(axis=(1,3))
# Per pixel, then over b x b blocks of whole pixels (every pixel of the block covered).
for b in (1,4):
    H,W=h//b,w//b
    c=covered[:H*b,:W*b].reshape(H,b,W,b).all(axis=(1,3))
    block=lambda a:a[:H*b,:W*b].reshape(H,b,W,b,3).mean(axis=(1,3))[c]
    dl=lab(block(lo)); dh=lab(block(hi)); de=de2000(dh,dl)
    print('  %dx%d: %5d  dE00 mean %.2f p95 %.2f  chroma far %.2f supersampled %.2f' % (b,b,c.sum(),de.mean(),np.percentile(de,95),np.hypot(dl[:,1],dl[:,2]).mean(),np.hypot(dh[:,1],dh[:,2]).mean()))
