"""Invariant: restart is exact with contact history. 20 steps in one run equal 10 steps, a
checkpoint, a restart and 10 steps: the checkpoint holds, besides the fluid, lambda and the
particles, the tangential springs of the open contacts (/contacts), and the contacts are summed
in a canonical order whatever neighbour list is in use (the restarted run builds a fresh one), so
the continued run repeats the same arithmetic; asserted to 1e-12 (fields, positions, velocities:
O(1) values, absolute; contact forces, torques and stresslets: relative to the largest contact
force, O(20)); and every other dataset and attribute of the final checkpoints and of series.h5 (but
wall_time) to 1e-12 of its largest magnitude (at least 1). Bitwise in practice.
Set-up: three free spheres with friction 0.5 in a sheared Couette cell (Re = 0.01, dt = 1e-3,
k_n = 1e5 prescribed, h_r = 0.01 a): spheres 1 and 2 stacked along y and pressed together by
opposite external forces (the shear slides them past each other: a tangential spring), sphere 3
pressed onto the lower wall, which moves at -3.2 along x (a wall spring). The test checks that
these contacts exist at every step of both runs and that the checkpoint at step 10 holds non-zero
springs, so the history really is exercised; and that the checkpoint's springs at step 20 agree
too. 2 ranks: the contact state is replicated and must be identical on both."""
import os
import h5py
import numpy as np
import fdsusp_testlib as T

DECK = """&domain box = 6.4, 6.4, 6.4, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, initial_flow = 'shear', velocity_tolerance = 1e-12, pressure_tolerance = 1e-12 /
&time dt = 1e-3, steps = {steps} /
&output directory = 'out', progress_every = 5 /
&particles number = 3,
  position(:,1) = 3.2, 2.2, 3.2, external_force(:,1) = 0, 18.84955592153876, 0,
  position(:,2) = 3.2, 4.206, 3.2, external_force(:,2) = 0, -18.84955592153876, 0,
  position(:,3) = 0.3, 1.006, 3.0, external_force(:,3) = 0, -18.84955592153876, 0 /
&contact roughness = 0.01, normal_stiffness = 1e5, friction = 0.5 /
"""
FIELDS = ['u', 'v', 'w', 'p', 'particles/position', 'particles/velocity', 'particles/omega']
SERIES = ['particles/position', 'particles/velocity', 'particles/omega', 'particles/force_hydro']
CONTACT = ['particles/force_contact', 'particles/torque_contact', 'particles/stresslet_contact']


def springs(d):
    with h5py.File(os.path.join(d, 'out', 'checkpoint.h5'), 'r') as f:
        g = f['contacts']
        n = int(g.attrs['count'][0])
        if n == 0:
            return np.zeros((0, 2), int), np.zeros((0, 3))
        return np.array(g['ids']), np.array(g['spring'])


a = T.scratch('contact_restart_straight')
T.run(T.write_deck(a, 'd.nml', DECK.format(steps=20)), a, np_ranks=T.RANKS)
b = T.scratch('contact_restart_split')
T.run(T.write_deck(b, 'd10.nml', DECK.format(steps=10)), b, np_ranks=T.RANKS)
ids, ups = springs(b)
T.check(len(ids) == 2 and [1, 2] in ids.tolist() and [3, -1] in ids.tolist(),
        'checkpoint at step 10 holds the springs of contacts (1,2) and (3, lower wall): %s' % ids.tolist())
norms = np.linalg.norm(ups, axis=1) if len(ups) else np.zeros(0)
T.check(len(norms) == 2 and norms.min() > 1e-4,
        'the springs are not zero: |Upsilon| = %s a' % ', '.join('%.2e' % v for v in norms))
_, out, _ = T.run(T.write_deck(b, 'd.nml', DECK.format(steps=20)), b, np_ranks=T.RANKS,
                  args=['-restart', os.path.join(b, 'out', 'checkpoint.h5')])
T.check('friction on' in out, "the run log's models line says contacts and friction are on")

sa, sb = T.series(os.path.join(a, 'out')), T.series(os.path.join(b, 'out'))
for s, what in ((sa, 'straight'), (sb, 'restarted')):
    T.check(len(s['step']) == 20 and np.all(s['contacts_pair'] == 1) and np.all(s['contacts_wall'] == 1),
            '%s run: 20 records, one pair and one wall contact at every step' % what)
ft = np.linalg.norm(sa['particles/force_contact'][-1, 0] - np.array([0, sa['particles/force_contact'][-1, 0, 1], 0]))
T.check(ft > 1.0, 'tangential contact force on sphere 1 at step 20: %.3f (friction is at work)' % ft)

fa = T.read_h5(os.path.join(a, 'out', 'checkpoint.h5'), FIELDS)
fb = T.read_h5(os.path.join(b, 'out', 'checkpoint.h5'), FIELDS)
for k in FIELDS:
    diff = np.abs(fa[k] - fb[k]).max()
    T.check(diff <= 1e-12, 'checkpoint %s: 20 steps vs 10 + restart + 10 (max diff %.1e <= 1e-12)' % (k, diff))
for k in SERIES:
    diff = np.abs(sa[k] - sb[k]).max()
    T.check(diff <= 1e-12, 'series %s identical (max diff %.1e <= 1e-12)' % (k, diff))
scale = np.abs(sa['particles/force_contact']).max()
for k in CONTACT:
    diff = np.abs(sa[k] - sb[k]).max() / scale
    T.check(diff <= 1e-12, 'series %s identical (max diff %.1e of max|F_c| = %.1f)' % (k, diff, scale))
T.compare_h5(os.path.join(a, 'out', 'checkpoint.h5'), os.path.join(b, 'out', 'checkpoint.h5'),
             '20 steps vs 10 + restart + 10, checkpoint')
T.compare_h5(os.path.join(a, 'out', 'series.h5'), os.path.join(b, 'out', 'series.h5'),
             '20 steps vs 10 + restart + 10, series', skip=('wall_time',))
ia, ua = springs(a)
ib, ub = springs(b)
T.check(np.array_equal(ia, ib) and np.abs(ua - ub).max() <= 1e-12,
        'the springs at step 20 agree (%d contacts)' % len(ia))
T.finish()
