"""Invariants of the Lees-Edwards boundaries (&domain y_boundary = 'lees-edwards', lubrication
dynamics):
1. a pair straddling the sliding boundary moves as the same pair inside the box: two rough,
   frictional spheres (eps_r = 1e-2, mu_d = 0.5) start at the relative position (-3a, 0.5a, 0),
   once at the centre of a 12a box and once across y = Ly (sphere 2 at y = 0.25a, its image above
   at 12.25a); over 8 strains (the boundary offset sweeps the box length 8 times) they approach,
   touch (contact, friction, lubrication at gaps down to 1e-2 a) and separate. Their separation
   (minimum image across the sliding boundary, from the recorded offset), relative velocity (the
   image's, U_2 + s gamma_dot Ly e_x) and contact forces must agree to round-off: only the
   arithmetic of the absolute positions differs (x + r vs x, rounding at ~1e-15 of 12a), which the
   stiff contact amplifies at most by its stiffness over the step; tolerances 1e-10 a on the
   separation, 1e-9 on the velocities and 1e-8 relative on the contact force (measured 1.7e-12,
   8.5e-12, 3e-11).
2. restart is exact: a dense sheared suspension (phi 0.3 packed at the start, 37 spheres in a
   8a box, rough frictional contacts, lubrication, &rheology over the whole box) run 300 steps
   equals 150 steps, a checkpoint, a restart and 150 steps: every dataset and attribute of the final
   checkpoints (positions, velocities, Adams-Bashforth history, contact springs, statistics, the
   boundary offset) and of series.h5 (wall_time excepted) agrees to 1e-12 of its largest magnitude
   (bitwise in practice), as tests/regression/test_restart.py asks of the DNS."""
import os
import shutil
import numpy as np
import fdsusp_testlib as T

PAIR = """&domain box = 12, 12, 12, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 2e-3, steps = 4000 /
&output directory = 'out', progress_every = 4000, series_every = 10 /
&particles number = 2, position(:,1) = 7.5, {y1}, 6.0, position(:,2) = 4.5, {y2}, 6.0 /
&contact roughness = 0.01, eps_bar = 0.05, friction = 0.5 /
"""
L = 12.0


def relative(outdir):
    s = T.series(outdir)
    x, u, off = s['particles/position'], s['particles/velocity'], s['lees_edwards_offset']
    d = x[:, 1] - x[:, 0]
    shift = -np.round(d[:, 1] / L)
    r = d.copy()
    r[:, 1] += shift * L
    r[:, 0] += shift * off
    r[:, [0, 2]] -= L * np.round(r[:, [0, 2]] / L)
    du = u[:, 1] - u[:, 0]
    du[:, 0] += shift * L
    return r, du, shift, s['particles/force_contact']


runs = {}
for name, y1, y2 in (('inside', 5.75, 6.25), ('across', 11.75, 0.25)):
    d = T.scratch('ld_lees_edwards_' + name)
    T.run(T.write_deck(d, 'p.nml', PAIR.format(y1=y1, y2=y2)), d)
    runs[name] = relative(os.path.join(d, 'out'))
(ra, ua, sa, fa), (rb, ub, sb, fb) = runs['inside'], runs['across']
gap = np.linalg.norm(ra, axis=1) - 2
T.check(gap.min() < 0.01 and np.abs(fa).max() > 1, 'the pair touches (closest gap %.2e a, contact force up to %.1f)'
        % (gap.min(), np.abs(fa).max()))
T.check((sb != 0).all() and (sa == 0).all(), 'the second pair straddles the sliding boundary throughout')
er = np.abs(ra - rb).max()
T.check(er <= 1e-10, 'separation across the boundary = inside: max difference %.1e a (<= 1e-10)' % er)
eu = np.abs(ua - ub).max()
T.check(eu <= 1e-9, 'relative velocity across = inside: max difference %.1e a gamma_dot (<= 1e-9)' % eu)
ef = np.abs(fa - fb).max() / np.abs(fa).max()
T.check(ef <= 1e-8, 'contact forces across = inside: max difference %.1e relative (<= 1e-8)' % ef)

DENSE = """&domain box = 8, 8, 8, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 5e-3, steps = {steps} /
&output directory = 'out', progress_every = 50, checkpoint_every = {every} /
&particles solid_fraction = 0.3, seed = 2 /
&contact roughness = 5e-3, friction = 0.5 /
&rheology discard_strain = 0.25, average_strain = 1.0, blocks = 2 /
"""
da = T.scratch('ld_lees_edwards_restart_a')
T.run(T.write_deck(da, 'd.nml', DENSE.format(steps=300, every=0)), da)
db = T.scratch('ld_lees_edwards_restart_b')
T.run(T.write_deck(db, 'd.nml', DENSE.format(steps=150, every=0)), db)
T.run(T.write_deck(db, 'd.nml', DENSE.format(steps=300, every=0)), db, args=['-restart', 'out/checkpoint.h5'])
names = T.compare_h5(os.path.join(da, 'out', 'checkpoint.h5'), os.path.join(db, 'out', 'checkpoint.h5'),
                     'restart, checkpoint')
T.check('@lees_edwards_offset' in names and 'rheology/accumulators' in names and any(n.startswith('contacts') for n in names),
        'restart: the checkpoint holds the boundary offset, the statistics and the contact springs')
T.compare_h5(os.path.join(da, 'out', 'series.h5'), os.path.join(db, 'out', 'series.h5'), 'restart, series',
             skip=('wall_time',))
sb = T.series(os.path.join(db, 'out'))
T.check(np.array_equal(sb['step'], np.arange(1, 301)), 'restart: series steps 1..300, each once')
T.check(float(T.h5_attr(os.path.join(da, 'out', 'checkpoint.h5'), 'lees_edwards_offset')[0]) > 0,
        'restart: the offset has moved (%.6f a)' % float(T.h5_attr(os.path.join(da, 'out', 'checkpoint.h5'),
                                                                  'lees_edwards_offset')[0]))
T.finish()
