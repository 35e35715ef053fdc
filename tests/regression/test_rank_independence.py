"""Invariant: the answer does not depend on the rank layout. Four free spheres in a walled Couette
cell driven along z as well (body force), 32 x 24 x 32 cells at a/Delta = 4, 30 steps with the
default direct (FFT) fluid solves, which are exact to round-off. The spheres are placed where the
Lambda carry reads edge and corner ghosts: two cross the periodic boundary x = 0 during the run
(shear along x), with centres on z rank boundaries (z = Lz/2: 2, 3, 4 and 8 ranks; z = Lz/4: 4 and 8
ranks), one sits across x = 0 on the rank boundary z = 3Lz/4, one across the periodic corner
x = 0, z = 0. All move along z too, so the trilinear weights of the diagonal corners are not small.
 1. 1, 2, 4 and 8 ranks (z slabs, 8 to 2 planes of cells each, --oversubscribe): particle velocity,
    omega, position and hydrodynamic stresslet at every step, and u, v, w, p and lambda_u/v/w of
    the final checkpoint, agree with 1 rank to 1e-12 of each quantity's largest magnitude;
 2. 15 steps on 2 ranks, a checkpoint, 15 more on 3 ranks (unequal slabs: 16, 8, 8 planes) agree
    with the 30 steps on 1 rank to the same tolerance.
Tolerance: the ranks sum the moments in another order and the transforms run on other slabs, a
few 1e-16 per step, which the free spheres carry on: measured at most 2.0e-14 (omega, the smallest
quantity: a torque-free sphere's rotation is a small difference). 1e-12 leaves a factor 50 and is
far below the error this test guards against: with the carry reading star-stencil ghosts, which
are never filled, 2 ranks differed by 3.7e-5 (velocity) and 2.0e-4 (omega), 8 ranks by 1.1e-3
and 7.0e-3 (doc/VALIDATION.md §2.6). About 8 s on 2 cores."""
import os
import re
import numpy as np
import fdsusp_testlib as T

# Lx = Lz: the restart refuses a checkpoint of a grid with n1 /= n3 ('dataset of the wrong shape
# for this grid': src/io/checkpoint.F90 compares HDF5's Fortran-order dimensions with n3, n2, n1)
LX, LZ = 8.0, 8.0
DECK = """&domain box = 8, 6, 8, cells_per_radius = 4, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, initial_flow = 'shear', body_force = 0, 0, 0.3 /
&time dt = 0.01, steps = {steps} /
&output directory = 'out', progress_every = 10 /
&particles number = 4, position(:,1) = 0.1, 1.5, 4.0, position(:,2) = 7.9, 4.5, 2.0,
  position(:,3) = 0.2, 4.4, 6.0, position(:,4) = 7.95, 3.0, 0.05 /
&lubrication model = 'none' /
"""
PARTICLES = ['particles/velocity', 'particles/omega', 'particles/position', 'particles/stresslet_hydro']
FIELDS = ['u', 'v', 'w', 'p', 'lambda_u', 'lambda_v', 'lambda_w']
TOL = 1e-12


def run(name, ranks, steps=30, args=(), d=None):
    d = d or T.scratch(name)
    deck = T.write_deck(d, 'd%d.nml' % steps, DECK.format(steps=steps))
    status, out, err = T.run(deck, d, np_ranks=ranks, args=args)
    grid = re.search(r'process grid (\d+) (\d+) (\d+)', out)
    T.check(grid is not None and [int(g) for g in grid.groups()] == [1, 1, ranks],
            '%s: %d ranks split the grid in z slabs (process grid %s)' % (name, ranks, ' x '.join(grid.groups()) if grid else '?'))
    return d


def results(d):
    s = T.series(os.path.join(d, 'out'))
    f = T.read_h5(os.path.join(d, 'out', 'checkpoint.h5'), FIELDS)
    return {**{k: s[k] for k in PARTICLES}, **f}


def compare(ref, other, what):
    for k in PARTICLES + FIELDS:
        scale = np.abs(ref[k]).max()
        if ref[k].shape != other[k].shape:
            T.check(False, '%s: %s has shape %s, 1 rank %s' % (what, k, other[k].shape, ref[k].shape))
            continue
        diff = np.abs(other[k] - ref[k]).max() / scale
        T.check(diff <= TOL, '%s: %s max difference %.1e of its largest (%.3g) <= %.0e' % (what, k, diff, scale, TOL))


ref = results(run('rank_independence_1', 1))
# the scene does what it must: spheres 1 and 2 cross x = 0 on the z boundaries of the slabs
pos = ref['particles/position']
for q, z_split in ((0, LZ / 2), (1, LZ / 4)):
    jumps = np.nonzero(np.abs(np.diff(pos[:, q, 0])) > LX / 2)[0]
    T.check(len(jumps) == 1 and abs(pos[jumps[0], q, 2] - z_split) < 0.5,
            'sphere %d crosses x = 0 (at step %s) with its centre within 0.5 a of the rank boundary z = %g'
            % (q + 1, jumps + 1, z_split))
T.check(np.abs(pos[-1, :, 2] - pos[0, :, 2]).min() > 0.2, 'every sphere moves along z too (>= %.2f a)'
        % np.abs(pos[-1, :, 2] - pos[0, :, 2]).min())

for n in (2, 4, 8):
    compare(ref, results(run('rank_independence_%d' % n, n)), '%d ranks vs 1' % n)

# restart on another rank count: 15 steps on 2 ranks, then 15 on 3
d = run('rank_independence_restart', 2, steps=15)
T.check(int(T.h5_attr(os.path.join(d, 'out', 'checkpoint.h5'), 'step')[0]) == 15, 'checkpoint at step 15 (2 ranks)')
run('rank_independence_restart', 3, args=['-restart', 'out/checkpoint.h5'], d=d)
compare(ref, results(d), '15 steps on 2 ranks + restart + 15 on 3 vs 30 on 1')
T.finish()
