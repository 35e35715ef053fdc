"""Invariant: the resolved fluid in a Lees-Edwards box (doc/METHOD.md §2.4; &domain y_boundary =
'lees-edwards' with &fluid model = 'resolved'; issue 46 item 2) is sheared by its sliding
boundary alone. Box 8a x 6a x 4a at a/Delta = 2 (16 x 12 x 8 cells, Delta = 0.5), rate 1.
A. Steady shear from the linear profile (initial_flow = 'shear', Crank-Nicolson, dt 0.05, 40
   steps: the offset gamma_dot Ly t passes Lx = 8 at t = 1.33 and wraps): u = gamma_dot (y - Ly/2)
   is an exact solution of the discrete problem at every offset (its images across the boundary
   are the linear profile continued), so every snapshot (t = 0.5, 1, 1.5, 2) holds it to 1e-13
   (round-off of the solves, ~1e-15 relative, of values ~3), v = w = 0 to 1e-13, the divergence
   column is 0 to 1e-13, the mean viscous stress across the boundary (tau_wall_bottom/top) is
   gamma_dot to 1e-12, and the offset column is gamma_dot Ly t_{n+1} mod Lx to 1e-12 a.
B. Start-up from rest (backward Euler, Re 0.01, dt 5e-4, 200 steps): u - gamma_dot (y - Ly/2) is
   then the sawtooth -gamma_dot (y - Ly/2), x-independent and periodic (the jump gamma_dot Ly
   across the boundary is what drives the flow), made of the grid modes sin(2 pi l (y - Ly/2)/Ly);
   each decays by g_l = 1/(1 + mu_l) a step, mu_l = dt/Re 4 sin^2(pi l/n_y)/Delta^2 (the
   eigenvalue of the 1D second difference). By step 150 the mode l = 2 has fallen to
   ((1 + mu_1)/(1 + mu_2))^150 = 3e-9 of l = 1, so the ratio of consecutive rate_of_change values
   (max|u^{n+1} - u^n|/dt, the amplitude of the slowest mode) is g_1 to 1e-8 (measured 4e-10).
   And the profile after 200 steps is linear plus the sawtooth's l = 1 component (its projection
   on the grid sine) times g_1^200, within 1e-6 of that component's size (the faster modes' remnant
   is < 1e-9 of it; measured 1e-10). Without the jump the fluid would stay at rest (a miss of
   O(gamma_dot Ly)); with it on the wrong side, the drive would change sign.
C. 2 ranks (z-slabs) give the start-up of 1 rank to 1e-12 of each column's largest value.
D. Restart: 40 steps against 20 + restart + 20 of A's deck (with the offset wrapping after the
   restart), checkpoint and series bitwise (rtol 0).
A few seconds on one core."""
import glob
import os
import h5py
import numpy as np
import fdsusp_testlib as T

LX, LY, H = 8.0, 6.0, 0.5
STEADY = """&domain box = 8.0, 6.0, 4.0, cells_per_radius = 2, y_boundary = 'lees-edwards', shear_rate = 1.0 /
&fluid initial_flow = 'shear' /
&time dt = 0.05, steps = {steps} /
&output directory = 'out', progress_every = 1000, fields_every = 10, checkpoint_every = 20 /
"""
STARTUP = """&domain box = 8.0, 6.0, 4.0, cells_per_radius = 2, y_boundary = 'lees-edwards', shear_rate = 1.0 /
&fluid reynolds = 0.01, viscous_theta = 1.0 /
&time dt = 5.0e-4, steps = 200 /
&output directory = 'out', progress_every = 1000, fields_every = 200 /
"""

# A. steady shear
d = T.scratch('le_fluid_steady')
T.run(T.write_deck(d, 'steady.nml', STEADY.format(steps=40)), d)
snapshots = sorted(glob.glob(os.path.join(d, 'out', 'fields_*.h5')))
T.check(len(snapshots) == 4, 'four snapshots (t = 0.5, 1, 1.5, 2)')
worst_u = worst_vw = 0.0
for path in snapshots:
    with h5py.File(path, 'r') as f:
        u, v, w = (np.array(f[c]) for c in 'uvw')    # (z, y, x), cell-centred
    y = (np.arange(u.shape[1]) + 0.5) * H
    worst_u = max(worst_u, np.max(np.abs(u - (y - LY / 2)[None, :, None])))
    worst_vw = max(worst_vw, np.max(np.abs(v)), np.max(np.abs(w)))
T.check(worst_u <= 1e-13, 'steady: u = gamma_dot (y - Ly/2) in every snapshot (largest miss %.1e)' % worst_u)
T.check(worst_vw <= 1e-13, 'steady: v = w = 0 (largest %.1e)' % worst_vw)
s = T.series(os.path.join(d, 'out'))
T.check(np.max(np.abs(s['divergence'])) <= 1e-13, 'steady: divergence column 0 (%.1e)' % np.max(np.abs(s['divergence'])))
miss = max(np.max(np.abs(s['tau_wall_bottom'] - 1)), np.max(np.abs(s['tau_wall_top'] - 1)))
T.check(miss <= 1e-12, 'steady: the viscous stress across the sliding boundary is gamma_dot (%.1e)' % miss)
offset = np.mod(LY * s['time'], LX)
miss = np.max(np.abs(s['lees_edwards_offset'] - offset))
T.check(miss <= 1e-12 and s['lees_edwards_offset'].max() > 7 and s['lees_edwards_offset'][-1] < 5,
        'steady: the offset is gamma_dot Ly t mod Lx at every record, wrapping past Lx (%.1e)' % miss)

# B. start-up from rest
re_, dt, ny = 0.01, 5.0e-4, int(LY / H)
d = T.scratch('le_fluid_startup')
T.run(T.write_deck(d, 'startup.nml', STARTUP), d)
s = T.series(os.path.join(d, 'out'))
mu = [dt / re_ * 4 * np.sin(np.pi * l / ny) ** 2 / H ** 2 for l in (1, 2)]
g = 1.0 / (1.0 + mu[0])
ratio = s['rate_of_change'][150:] / s['rate_of_change'][149:-1]
miss = np.max(np.abs(ratio / g - 1))
T.check(miss <= 1e-8, 'start-up: the slowest mode decays by 1/(1 + mu_1) = %.12f a step from step 150 '
        '(largest relative miss %.1e; l = 2 has fallen to %.0e of it)' % (g, miss, ((1 + mu[0]) / (1 + mu[1])) ** 150))
with h5py.File(sorted(glob.glob(os.path.join(d, 'out', 'fields_*.h5')))[-1], 'r') as f:
    profile = np.array(f['u']).mean(axis=(0, 2))
yc = (np.arange(ny) + 0.5) * H
disturbance = profile - (yc - LY / 2)
# the sawtooth's l = 1 sine coefficient on the grid, decayed by g^200
s_c = yc - LY / 2
mode = np.sin(2 * np.pi * s_c / LY)
amplitude0 = np.dot(-s_c, mode) / np.dot(mode, mode)
predicted = amplitude0 * g ** 200 * mode
miss = np.max(np.abs(disturbance - predicted))
T.check(miss <= 1e-6 * np.max(np.abs(predicted)),
        'start-up: after 200 steps u - gamma_dot (y - Ly/2) is the l = 1 mode of the sawtooth decayed by '
        'g^200 (amplitude %.6f, miss %.1e)' % (np.max(np.abs(predicted)), miss))

# C. two ranks
d2 = T.scratch('le_fluid_startup_2')
T.run(T.write_deck(d2, 'startup.nml', STARTUP), d2, np_ranks=T.RANKS)
T.compare_h5(os.path.join(d, 'out', 'series.h5'), os.path.join(d2, 'out', 'series.h5'),
             'start-up, %d ranks against 1' % T.RANKS, rtol=1e-12, skip=('wall_time',))

# D. restart
a = T.scratch('le_fluid_restart_straight')
T.run(T.write_deck(a, 'd.nml', STEADY.format(steps=40)), a)
b = T.scratch('le_fluid_restart_split')
T.run(T.write_deck(b, 'half.nml', STEADY.format(steps=20)), b)
T.run(T.write_deck(b, 'd.nml', STEADY.format(steps=40)), b, args=['-restart', 'out/checkpoint.h5'])
T.compare_h5(os.path.join(a, 'out', 'checkpoint.h5'), os.path.join(b, 'out', 'checkpoint.h5'),
             'restart: 40 steps against 20 + restart + 20, checkpoint', rtol=0)
T.compare_h5(os.path.join(a, 'out', 'series.h5'), os.path.join(b, 'out', 'series.h5'),
             'restart: series', rtol=0, skip=('wall_time',))
T.finish()
