"""Invariant: stress control of the DNS with spheres in a Lees-Edwards box (doc/INPUT.md "&shear"
control = 'stress'; doc/METHOD.md §7.4; issue 46) sets the rate of each step so that the mean shear
stress of the box is the asked S, exactly, and gives back the rate of a rate-controlled run at the
stress that run measured.
Without walls the mean shear stress is the box's: eta gamma_dot (the fluid's mean viscous stress,
exactly: u - gamma_dot y is periodic up to a shift in x) plus the spheres' stresslets over the
volume, sum_p (S^h + S^c)_xy / V, which the statistics sample as rate + core/stress_hydro_xy +
core/stress_contact_xy (the core is the whole box). The step is affine in the rate (the boundary's
jump in the fluid, the images' speed, the links' drives, the implicit contacts), so the stress
control solves one scalar equation from two particle solves and the fictitious domain's stresslet
evaluated without writing (fictitious_domain_solve_stress, shear_stresslet).
Scene: 31 rough frictional spheres (phi 0.25, mu_d 0.5, eps_r 0.05), 8a cube, a/Delta = 2
(lubrication 'simple': no table at this resolution), Re 0.01, backward Euler, dt 2e-3, 1200 steps
(strain 2.4), from the linear profile.
A. rate control (rate 1): S = <rate + core stresses_xy> over the window (steps > 200, 5 blocks;
   block mean and standard error).
B. stress control at S:
   1. at every record the stress the step solved for is S (shear/stress, to 1e-12 relative), and so
      is the statistics' own sum over the stresslets the update then wrote (to 1e-12): the affine
      evaluation of the stress (the fictitious domain's stresslet from u~ and U without writing,
      the links' and contacts' corrections) is the stress the step leaves;
   2. the boundary slides at the rate the fluid's step took, the last step's (doc/METHOD.md §7.4):
      the strain grows by dt gamma_dot^{n-1} a step (the reference rate 1 on the first; series'
      shear/strain is gamma(t_n)) and the offset after a step is the strain then times Ly mod Lx,
      to 1e-12;
   3. the mean rate over the window gives back the imposed rate 1 within 3 combined standard
      errors (its own block error and err(S)/S carried into it, as test_protocol_stress_dns).
C. restart: 100 steps against 50 + restart + 50 under stress control, series bitwise.
About 40 s on one core; C runs beside B."""
import os
from concurrent.futures import ThreadPoolExecutor
import numpy as np
import fdsusp_testlib as T

DT, BOX = 2.0e-3, 8.0
DECK = """&domain box = 8.0, 8.0, 8.0, cells_per_radius = 2, y_boundary = 'lees-edwards' /
&shear {shear} /
&fluid reynolds = 0.01, viscous_theta = 1.0, initial_flow = 'shear' /
&time dt = 2.0e-3, steps = {steps} /
&output directory = '{out}', progress_every = 100000, checkpoint_every = 50 /
&particles solid_fraction = 0.25, seed = 1 /
&contact roughness = 0.05, friction = 0.5 /
&lubrication model = 'simple' /
&rheology discard_strain = 0.4, average_strain = 2.0, blocks = 5 /
"""
DISCARD, BLOCKS = 200, 5


def block_mean(x):
    b = np.array([m.mean() for m in np.array_split(x, BLOCKS)])
    return b.mean(), b.std(ddof=1) / np.sqrt(BLOCKS)


def box_stress(s):
    return s['shear/rate'] + s['core/stress_hydro'][:, 3] + s['core/stress_contact'][:, 3]


d = T.scratch('protocol_stress_dns_le')
T.run(T.write_deck(d, 'rate.nml', DECK.format(shear='rate = 1.0', steps=1200, out='rate')), d)
s = T.series(os.path.join(d, 'rate'))
window = s['step'] > DISCARD
S, S_err = block_mean(box_stress(s)[window])
T.check(np.all(s['shear/rate'] == 1.0) and S_err > 0, 'rate control: S = %.4f +- %.4f' % (S, S_err))

shear = "control = 'stress', stress = %.15g" % S
# B's run on one core while C's three (independent runs, in directories of their own) run on the other
stress_run = ThreadPoolExecutor(max_workers=1).submit(
    T.run, T.write_deck(d, 'stress.nml', DECK.format(shear=shear, steps=1200, out='stress')), d)
a = T.scratch('protocol_stress_dns_le_straight')
T.run(T.write_deck(a, 'd.nml', DECK.format(shear=shear, steps=100, out='out')), a)
b = T.scratch('protocol_stress_dns_le_split')
T.run(T.write_deck(b, 'half.nml', DECK.format(shear=shear, steps=50, out='out')), b)
T.run(T.write_deck(b, 'd.nml', DECK.format(shear=shear, steps=100, out='out')), b, args=['-restart', 'out/checkpoint.h5'])
stress_run.result()

s = T.series(os.path.join(d, 'stress'))
rate = s['shear/rate']
miss = np.max(np.abs(s['shear/stress'] - S)) / S
T.check(miss < 1e-12, 'the stress each step solved for is S (largest relative miss %.1e)' % miss)
miss = np.max(np.abs(box_stress(s) - S)) / S
T.check(miss < 1e-12, 'the statistics\' own sum, rate + sum of the stresslets / V, is S at every record (%.1e)' % miss)
advance = np.r_[1.0, rate[:-1]]          # the rate the boundary slid at in each step
after = np.cumsum(advance * DT)            # the strain after each step
miss = np.max(np.abs(s['shear/strain'] - (after - advance * DT)))
T.check(miss < 1e-12, 'the strain (recorded at t_n) grows by dt gamma_dot^(n-1) a step (%.1e)' % miss)
gap = np.mod(s['lees_edwards_offset'] - after * BOX + BOX / 2, BOX) - BOX / 2
T.check(np.max(np.abs(gap)) < 1e-12, 'the offset after each step is that strain times Ly mod Lx (%.1e)'
        % np.max(np.abs(gap)))
mean, err = block_mean(rate[window])
tolerance = 3 * np.hypot(err, S_err / S)
T.check(abs(mean - 1) <= tolerance, 'mean rate at the measured S: %.4f +- %.4f, 1 within %.3f (3 combined errors); '
        'the rate ranges over %.2f .. %.2f' % (mean, err, tolerance, rate.min(), rate.max()))

# C (run beside B's run above)
T.compare_h5(os.path.join(a, 'out', 'series.h5'), os.path.join(b, 'out', 'series.h5'),
             'restart under stress control, 100 against 50 + 50: series', rtol=0, skip=('wall_time',))
T.finish()
