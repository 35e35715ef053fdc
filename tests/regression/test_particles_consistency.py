"""Invariants of the particle step that hold whatever the physics:
 1. particle order: permuting the particles of the deck permutes the results and nothing else
    (every moment is a sum over each particle's own faces; a face shared by two spheres goes to the
    one covering more of it, which does not depend on the order). Asserted to 1e-12 on positions
    and velocities after 20 steps;
 2. decomposition: 1 and 2 ranks give the same particle velocities and fields after 20 steps to
    1e-10, with the fluid solvers run to a relative tolerance of 1e-12 (the moments are summed
    over ranks in another order and the parallel smoothers differ; the tight tolerance makes that
    difference round-off);
 3. restart: 20 steps equal 10 steps, a checkpoint, a restart and 10 steps, bitwise in practice,
    asserted to 1e-12: the checkpoint holds lambda, positions and the Adams-Bashforth history.
Three free spheres in a small Couette cell (one close to a periodic boundary, so its faces wrap
and, on 2 ranks, fall on both sides of the processor boundary)."""
import os
import numpy as np
import fdsusp_testlib as T

POS = [(1.3, 3.0, 3.1), (4.1, 4.6, 3.5), (3.2, 1.9, 5.9)]
DECK = """&domain box = 6.4, 6.4, 6.4, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, initial_flow = 'shear', velocity_tolerance = 1e-12, pressure_tolerance = 1e-12 /
&time dt = 2e-3, steps = {steps} /
&output directory = 'out', progress_every = 5 /
&particles number = 3, {positions} /
"""


def deck(d, order, steps):
    pos = ', '.join('position(:,%d) = %r, %r, %r' % ((i + 1,) + POS[p]) for i, p in enumerate(order))
    return T.write_deck(d, 'p.nml', DECK.format(steps=steps, positions=pos))


def results(d):
    s = T.series(os.path.join(d, 'out'))
    f = T.read_h5(os.path.join(d, 'out', 'checkpoint.h5'), ['u', 'v', 'w', 'p', 'particles/position'])
    return s, f


d1 = T.scratch('particles_order_a')
T.run(deck(d1, [0, 1, 2], 20), d1)
s1, f1 = results(d1)
d2 = T.scratch('particles_order_b')
T.run(deck(d2, [2, 0, 1], 20), d2)
s2, f2 = results(d2)
perm = [1, 2, 0]   # particle k of run a is particle perm[k] of run b
for name in ('particles/velocity', 'particles/omega', 'particles/position'):
    diff = np.abs(s1[name] - s2[name][:, perm, :]).max()
    T.check(diff <= 1e-12, 'order: %s equal after permutation (max diff %.1e <= 1e-12)' % (name, diff))
diff = max(np.abs(f1[k] - f2[k]).max() for k in ('u', 'v', 'w'))
T.check(diff <= 1e-12, 'order: velocity fields equal (max diff %.1e <= 1e-12)' % diff)

d3 = T.scratch('particles_ranks2')
T.run(deck(d3, [0, 1, 2], 20), d3, np_ranks=T.RANKS)
s3, f3 = results(d3)
for name in ('particles/velocity', 'particles/omega', 'particles/force_hydro'):
    diff = np.abs(s1[name] - s3[name]).max()
    T.check(diff <= 1e-10, 'ranks: %s on 1 and %d ranks (max diff %.1e <= 1e-10)' % (name, T.RANKS, diff))
diff = max(np.abs(f1[k] - f3[k]).max() for k in ('u', 'v', 'w', 'p'))
T.check(diff <= 1e-10, 'ranks: fields on 1 and %d ranks (max diff %.1e <= 1e-10)' % (T.RANKS, diff))

d4 = T.scratch('particles_restart')
T.run(deck(d4, [0, 1, 2], 10), d4)
T.run(deck(d4, [0, 1, 2], 20), d4, args=['-restart', os.path.join(d4, 'out', 'checkpoint.h5')])
s4, f4 = results(d4)
for name in ('u', 'v', 'w', 'p', 'particles/position'):
    diff = np.abs(f1[name] - f4[name]).max()
    T.check(diff <= 1e-12, 'restart: %s after 10 + 10 steps equals 20 steps (max diff %.1e <= 1e-12)' % (name, diff))
diff = np.abs(s1['particles/velocity'] - s4['particles/velocity']).max()
T.check(len(s4['step']) == 20 and diff <= 1e-12,
        'restart: series holds 20 records, particle velocities equal (max diff %.1e)' % diff)
T.finish()
