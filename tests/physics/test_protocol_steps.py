"""Invariant: steps of rate or of stress (doc/INPUT.md "&shear" protocol 'steps'; issue 46) change
the imposed level exactly where the deck says, and the step across a change is consistent.
A. Lubrication dynamics, rate control, steps by strain: 49 rough frictional spheres (phi 0.4,
   Lees-Edwards, 8a box, dt 5e-3, reference rate 2), rates 1, 2, -0.5 from the accumulated
   |strain| 0, 0.5, 1.5, 500 steps:
   1. the rate changes at the records of steps 101 and 201 only (0.5 = 100 steps of 1 x dt, 1.5 =
      0.5 + 100 steps of 2 x dt) and is the level at every record;
   2. the strain is the integral of the rate, piecewise linear (to 1e-12);
   3. the step across a jump of the rate is consistent: its spheres move by forward Euler and the
      implicit contacts predict that same motion, so the largest contact overlap stays below h_r/2
      (measured 0.32 h_r; with the contacts predicting the Adams-Bashforth motion while the
      spheres moved by Euler, the run stopped on an overlap of 1.4 h_r right after the jump).
B. DNS, the fluid alone between walls, stress control, steps by time (4a cube, a/Delta 2, Re
   0.01, backward Euler, dt 0.01), stresses 1 then 3 from t = 1.5, 300 steps: the mean wall
   stress is the level at every record (to 1e-12), the first record at the new level is that of
   t_n = 1.5, and the rate has reached the Couette rate S/eta of each level before the next (1 at
   t_n = 1.49, 3 at the end, to 1e-12: 150 steps are 9 relaxation times of the slowest mode).
C. Lubrication dynamics, stress control, steps by time (A's scene, reference rate 1), stresses 8
   then 12 from t = 0.5, 200 steps: shear/stress is the level at every record (to 1e-12
   relative), and the strain advances by the spheres' step: dt (3/2 rate_n - 1/2 rate_n-1), by
   forward Euler (dt rate_n) on the first step and on the step of the jump (to 1e-12).
About 15 s on one core."""
import os
import numpy as np
import fdsusp_testlib as T

DT = 5.0e-3
LD = """&domain box = 8.0, 8.0, 8.0, y_boundary = 'lees-edwards' /
&shear {shear} /
&fluid model = 'none' /
&time dt = 5.0e-3, steps = {steps} /
&output directory = '{out}', progress_every = 100000 /
&particles solid_fraction = 0.4, seed = 1 /
&contact roughness = 5.0e-3, friction = 0.5 /
&rheology discard_strain = 0.0, average_strain = {average}, blocks = 2 /
"""
d = T.scratch('protocol_steps')
FLUID = """&domain box = 4.0, 4.0, 4.0, cells_per_radius = 2 /
&shear control = 'stress', protocol = 'steps', step_by = 'time', levels = 2, step_at = 0.0, 1.5,
       step_level = 1.0, 3.0 /
&fluid reynolds = 0.01, viscous_theta = 1.0 /
&time dt = 1.0e-2, steps = 300 /
&output directory = 'fluid', progress_every = 1000 /
"""
RATE_STEPS = "rate = 2.0, protocol = 'steps', levels = 3, step_at = 0.0, 0.5, 1.5, step_level = 1.0, 2.0, -0.5"
STRESS_STEPS = ("control = 'stress', protocol = 'steps', step_by = 'time', levels = 2, step_at = 0.0, 0.5, "
                "step_level = 8.0, 12.0")
# the three runs are independent (an output directory each): run together, two at a time
T.run_many([dict(deck=T.write_deck(d, 'rate.nml', LD.format(shear=RATE_STEPS, steps=500, out='rate', average=4.9)), cwd=d),
            dict(deck=T.write_deck(d, 'stress.nml', LD.format(shear=STRESS_STEPS, steps=200, out='stress',
                                                                average=0.95)), cwd=d),
            dict(deck=T.write_deck(d, 'fluid.nml', FLUID), cwd=d)])

# A. rate steps by strain
s = T.series(os.path.join(d, 'rate'))
rate, step = s['shear/rate'], s['step']
changes = step[1:][rate[1:] != rate[:-1]]
T.check(list(changes) == [101, 201], 'A: the rate changes at steps 101 and 201 only: %s' % list(changes))
level = np.where(step <= 100, 1.0, np.where(step <= 200, 2.0, -0.5))
T.check(np.array_equal(rate, level), 'A: the rate is the level at every record')
n = step - 1
expected = np.where(n <= 100, n * DT, np.where(n <= 200, 0.5 + 2 * (n - 100) * DT, 1.5 - 0.5 * (n - 200) * DT))
miss = np.max(np.abs(s['shear/strain'] - expected))
T.check(miss < 1e-12, 'A: the strain is the integral of the levels (%.1e)' % miss)
overlap = np.max(s['contact_overlap_over_roughness'])
T.check(overlap < 0.5, 'A: the largest contact overlap stays below h_r/2 across the jumps (%.3f h_r)' % overlap)

# B. the fluid alone, stress steps by time (run above)
s = T.series(os.path.join(d, 'fluid'))
t_n = s['time'] - 1.0e-2
level = np.where(t_n < 1.5 - 1e-9, 1.0, 3.0)
tau = 0.5 * (s['tau_wall_bottom'] + s['tau_wall_top'])
miss = max(np.max(np.abs(tau - level)), np.max(np.abs(s['shear/stress'] - level)))
T.check(miss < 1e-12, 'B: the mean wall stress is the level at every record (%.1e)' % miss)
first = np.argmax(level == 3.0)
T.check(abs(t_n[first] - 1.5) < 1e-9, 'B: the first record at stress 3 is that of t_n = 1.5 (%.4f)' % t_n[first])
rate = s['shear/rate']
T.check(abs(rate[first - 1] - 1.0) < 1e-12 and abs(rate[-1] - 3.0) < 1e-12,
        'B: the rate reaches S/eta at each level: %.15f, %.15f' % (rate[first - 1], rate[-1]))

# C. lubrication dynamics, stress steps by time (run above)
s = T.series(os.path.join(d, 'stress'))
step, rate = s['step'], s['shear/rate']
level = np.where(step <= 100, 8.0, 12.0)
miss = np.max(np.abs(s['shear/stress'] - level) / level)
T.check(miss < 1e-12, 'C: the stress each step solved for is the level (8, then 12 from step 101; %.1e)' % miss)
euler = (step == 1) | (step == 101)
advance = np.where(euler, rate, 1.5 * rate - 0.5 * np.r_[rate[0], rate[:-1]])
miss = np.max(np.abs(np.diff(s['shear/strain']) - DT * advance[:-1]))
T.check(miss < 1e-12, 'C: the strain advances with the spheres\' step, Euler on the first and on the jump (%.1e)' % miss)
T.finish()
