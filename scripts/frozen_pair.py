#!/usr/bin/env python3
"""The steady free mobility of a pair in shear (doc/VALIDATION.md §4.4): two spheres frozen in the
8 x 10 x 8 Couette cell (motion 'frozen': force- and torque-free velocities at a fixed
configuration, pseudo-time to the steady state by Aitken), full lubrication correction, at each
resolution given and gaps 0.01, 0.1, 0.3. Prints the radial velocity of each sphere relative to
the undisturbed flow against the exact two-sphere value: force-free along the line of centres d,
-6 pi (XA11 - XA12) (U1 - U_inf).d + 4 pi (XG11 - XG12) d.E.d = 0 (equal spheres: the squeeze
decouples from rotation and sliding), i.e. (U1 - U_inf).d = (2/3)(XG11 - XG12)/(XA11 - XA12) d.E.d.
    scripts/frozen_pair.py 4,5,6      (work in out/frozen_check; ~2 min on 2 cores)"""
import sys, os, numpy as np, h5py
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import calibrate as C
from resistance_exact import pair_scalars, NAMES
I={n:k for k,n in enumerate(NAMES)}
E=np.array([[0,0.5,0],[0.5,0,0],[0,0,0]]); om=np.array([0,0,-0.5]); PI=np.pi
cells=[int(c) for c in sys.argv[1].split(',')]; gaps=[0.01,0.1,0.3]
d=np.array([0.6,-0.6,0.53]); d/=np.linalg.norm(d)
L,LW=8.0,10.0
work=os.path.join(C.ROOT, 'out', 'frozen_check'); os.makedirs(work,exist_ok=True)
r=C.Runner(work,2)
for n in cells:
    h=1.0/n; off=np.array([0.29,0.71,0.43])*h
    cc=np.array([L/2,LW/2,L/2])+off
    uc=lambda x: np.array([x[1]-LW/2,0,0])
    for g in gaps:
        y1,y2=cc-(1+g/2)*d, cc+(1+g/2)*d
        out=r.add(f'a{n}_g{g}', box=(L,LW,L), walls=True, shear=1.0, spheres=[(y1,uc(y1),om),(y2,uc(y2),om)], h=h, model='full')
        t=open(out+'.nml').read().replace("motion = 'resistance'","motion = 'frozen'"); open(out+'.nml','w').write(t)
r.run()
ded=d@E@d
for n in cells:
    h=1.0/n; off=np.array([0.29,0.71,0.43])*h; cc=np.array([L/2,LW/2,L/2])+off
    for g in gaps:
        y1=cc-(1+g/2)*d
        with h5py.File(f'{work}/a{n}_g{g}/series.h5') as f:
            V=C.aitken(f['particles/velocity'][:])
        ex=pair_scalars(g)
        exact=(2/3)*(ex[I['XG11']]-ex[I['XG12']])/(ex[I['XA11']]-ex[I['XA12']])*ded
        u1=(V[0]-np.array([y1[1]-LW/2,0,0]))@d
        u2=(V[1]-np.array([(cc+(1+g/2)*d)[1]-LW/2,0,0]))@d
        print(f'a/D {n} gap {g}: (U1-Uinf).d {u1:+.5f} (U2-Uinf).d {u2:+.5f} exact {exact:+.5f} ({100*(u1/exact-1):+.2f} %)')
