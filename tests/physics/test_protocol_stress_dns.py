"""Invariant: stress control of the DNS with spheres between walls (doc/INPUT.md "&shear" control =
'stress'; doc/METHOD.md §7.4; issue 46) sets the walls' speed so that the mean wall shear stress is
the asked S at every step, exactly, and gives back the rate of a rate-controlled run at the wall
stress that run measured.
The mean wall shear stress is the force on the walls per area: the grid's viscous stress on each
wall (tau_wall_bottom, tau_wall_top) and the force of the spheres on the walls through the
sphere-wall lubrication links and the wall contacts (the columns wall_force_lubrication,
wall_force_contact: the force of the lower and the upper wall on the spheres),
  sigma_w = (tau_bottom + tau_top)/2 + (F_top,x - F_bottom,x)/(2 Lx Lz).
Scene: 31 rough frictional spheres (phi 0.25, mu_d 0.5; eps_r 0.05, ten times the paper's, so
that spheres touch the walls: at 5e-3 the wall lubrication keeps them off), 8a cube between
walls, a/Delta = 2 (lubrication model 'simple': no table at this resolution), Re 0.01, backward
Euler, dt 2e-3, 1200 steps (strain 2.4), from the Couette profile.
A. rate control (rate 1): the wall columns hold the walls' share as the spheres' own forces do:
   the x sum over the spheres of particles/force_contact is the x sum of wall_force_contact over
   the two walls (the pair contacts cancel, action = reaction, exactly: to 1e-12 of the largest
   contact force); S = <sigma_w> over the window (steps > 200, 5 blocks; block mean and its
   standard error). Momentum balance across the gap: in steady flow the mean shear stress is the
   same at every height (the fluid's momentum changes by Re d<u>/dt, nothing over the window), so
   the core's, summary.json tau = eta_r gamma_dot_core from the spheres' stresslets (the same
   window and blocks, doc/RHEOLOGY.md), is S within 3 combined standard errors: a check of the
   walls' share against quantities the wall columns do not enter. Measured 2026-11-28: S = 2.945
   +- 0.177 (fluid 1.955, wall lubrication 0.828, wall contacts 0.162), core 2.844 +- 0.193.
B. stress control at S:
   1. at every record the stress the step solved for is S (shear/stress, to 1e-12 relative: the
      coupled step is affine in the rate, so the one scalar equation is solved exactly), and so is
      sigma_w summed here from the wall columns (to 1e-12), and by
      fdsusp.protocols.wall_shear_stress (to 1e-12);
   2. the strain advances with the walls, dt gamma_dot^n each step (to 1e-12);
   3. wall contacts and wall lubrication are in the steps (their share is not zero);
   4. the mean rate over the same window gives back the imposed rate 1 within 3 combined standard
      errors: its own block error and the error of S carried into the rate, err(S)/S (the wall
      stress grows nearly in proportion to the rate). Measured 2026-11-28: S = 2.945 +- 0.177,
      mean rate 0.987 +- 0.057 (0.05 of the tolerance 0.247; the rate ranges over 0.83 .. 1.35).
C. the protocols under stress control, 150 steps each: 'oscillatory' (S 2.3, T 0.25) has the stress
   2.3 sin(2 pi t_n/T) at every record, 'steps' by time (2.3, 4, 1 from t = 0, 0.1, 0.2) the
   levels from steps 51 and 101 on, each to 1e-12, the rate rising and falling with the level.
D. the step is affine in the walls' speed (doc/METHOD.md §7.4), checked end to end: from the same
   checkpoint (the eps_r 5e-3 scene, k_n given so that it does not follow the reference rate, at
   the first step of the first 200 with a pair contact under friction and no wall contact, whose
   explicit force takes the last step's rate by design), one stress-controlled step and one
   rate-controlled step at the rate it found (a branch) give the same spheres, Lambda and fluid to
   1e-9 of each field's largest value: the superposition of the step at the last rate and the
   homogeneous response against a step taken at that rate from the start. Measured 2026-11-28 at
   step 81: 4.9e-13 (the particle CG stops at a relative residual of 1e-12; the FFT solves are exact);
   a rate-dependent term left out of the homogeneous step (a link's drive, the walls' velocity in
   the implicit contacts) would differ by its share of the step, orders of magnitude above.
About 25 s on one core (40 s on the loaded 2-core machine); C and D run beside A's first run."""
import json
import os
import shutil
from concurrent.futures import ThreadPoolExecutor
import numpy as np
import fdsusp_testlib as T
from fdsusp import protocols

DT, BOX = 2.0e-3, 8.0
AREA = BOX * BOX
DECK = """&domain box = 8.0, 8.0, 8.0, cells_per_radius = 2 /
&shear {shear} /
&fluid reynolds = 0.01, viscous_theta = 1.0, initial_flow = 'shear' /
&time dt = 2.0e-3, steps = {steps} /
&output directory = '{out}', progress_every = 100000 /
&particles solid_fraction = 0.25, seed = 1 /
&contact roughness = 0.05, friction = 0.5 /
&lubrication model = 'simple' /
&rheology discard_strain = 0.4, average_strain = 2.0, blocks = 5 /
"""
DISCARD, BLOCKS = 200, 5


def block_mean(x):
    """Mean of the block means over BLOCKS equal blocks, and its standard error (ddof 1)."""
    b = np.array([m.mean() for m in np.array_split(x, BLOCKS)])
    return b.mean(), b.std(ddof=1) / np.sqrt(BLOCKS)


def wall_stress(s):
    """sigma_w of every record from the series' columns (wall columns: record, wall, component)."""
    f = s['wall_force_lubrication'] + s['wall_force_contact']
    return 0.5 * (s['tau_wall_bottom'] + s['tau_wall_top']) + (f[:, 1, 0] - f[:, 0, 0]) / (2.0 * AREA)


d = T.scratch('protocol_stress_dns')
# A's rate-controlled run goes on one core while C and D, which do not need its S, run on the other
# (independent runs, each in its own output directory); A and B follow D
rate_run = ThreadPoolExecutor(max_workers=1).submit(
    T.run, T.write_deck(d, 'rate.nml', DECK.format(shear='rate = 1.0', steps=1200, out='rate')), d)
# C. the protocols of the stress
T.run(T.write_deck(d, 'osc.nml', DECK.format(shear="control = 'stress', stress = 2.3, protocol = 'oscillatory', "
                                             "period = 0.25", steps=150, out='osc')), d)
s = T.series(os.path.join(d, 'osc'))
miss = np.max(np.abs(s['shear/stress'] - 2.3 * np.sin(2 * np.pi * (s['step'] - 1) * DT / 0.25)))
miss = max(miss, np.max(np.abs(wall_stress(s) - s['shear/stress'])))
T.check(miss < 1e-12 and s['shear/rate'].min() < 0 < s['shear/rate'].max(),
        'oscillation: the wall stress is 2.3 sin(2 pi t_n/T) at every record, the rate changes sign (%.1e)' % miss)
T.run(T.write_deck(d, 'steps.nml', DECK.format(shear="control = 'stress', protocol = 'steps', step_by = 'time', "
                                               "levels = 3, step_at = 0.0, 0.1, 0.2, step_level = 2.3, 4.0, 1.0",
                                               steps=150, out='steps')), d)
s = T.series(os.path.join(d, 'steps'))
level = np.where(s['step'] < 51, 2.3, np.where(s['step'] < 101, 4.0, 1.0))
miss = max(np.max(np.abs(s['shear/stress'] - level)), np.max(np.abs(wall_stress(s) - level)))
r = s['shear/rate']
T.check(miss < 1e-12 and r[95] > r[45] > r[145] > 0,
        'steps: the wall stress is 2.3, 4, 1 from steps 1, 51, 101 (%.1e); the rate follows (%.3f, %.3f, %.3f)'
        % (miss, r[45], r[95], r[145]))

# D. the step under stress control is the rate-controlled step at the rate it found
AFFINE = DECK.replace('roughness = 0.05, friction = 0.5', 'roughness = 5.0e-3, friction = 0.5, normal_stiffness = 5.0e6') \
    .replace("&rheology discard_strain = 0.4, average_strain = 2.0, blocks = 5 /\n", '')
STRESS = "control = 'stress', stress = 2.9"
T.run(T.write_deck(d, 'scan.nml', AFFINE.format(shear=STRESS, steps=200, out='scan')), d)
s = T.series(os.path.join(d, 'scan'))
candidates = s['step'][(s['contacts_pair'] > 0) & (s['contacts_wall'] == 0)]
T.check(len(candidates) > 0 and candidates[0] > 1, 'a step with a pair contact and no wall contact: step %s'
        % (candidates[0] if len(candidates) else None))
n = int(candidates[0])
T.run(T.write_deck(d, 'to.nml', AFFINE.format(shear=STRESS, steps=n - 1, out='affine')), d)
shutil.copy(os.path.join(d, 'affine', 'checkpoint.h5'), os.path.join(d, 'before.h5'))
T.run(T.write_deck(d, 'on.nml', AFFINE.format(shear=STRESS, steps=n, out='affine')), d,
      args=['-restart', 'affine/checkpoint.h5'])
found = T.series(os.path.join(d, 'affine'))['shear/rate'][-1]
T.run(T.write_deck(d, 'branch.nml', AFFINE.format(shear='rate = %.17g' % found, steps=n, out='branch')), d,
      args=['-branch', 'before.h5'])
worst = 0.0
for name in ('particles/position', 'particles/velocity', 'particles/omega', 'lambda_u', 'lambda_v', 'lambda_w',
             'u', 'v', 'w', 'p'):
    a, b = (T.read_h5(os.path.join(d, run, 'checkpoint.h5'), [name])[name] for run in ('affine', 'branch'))
    worst = max(worst, np.max(np.abs(a - b)) / np.max(np.abs(a)))
T.check(worst < 1e-9, 'step %d under stress control (rate %.6f) = the rate-controlled step at that rate: spheres, '
        'Lambda, fluid within %.1e of each field\'s largest' % (n, found, worst))
# A. rate control
rate_run.result()
s = T.series(os.path.join(d, 'rate'))
spheres = s['particles/force_contact'][:, :, 0].sum(axis=1)
walls = s['wall_force_contact'][:, :, 0].sum(axis=1)
scale = np.max(np.abs(s['particles/force_contact']))
miss = np.max(np.abs(spheres - walls)) / scale
T.check(miss < 1e-12 and np.max(np.abs(walls)) > 0,
        'rate control: the spheres\' contact forces sum to the walls\' (pairs cancel; %.1e of the largest)' % miss)
sigma = wall_stress(s)
window = s['step'] > DISCARD
S, S_err = block_mean(sigma[window])
T.check(np.all(s['shear/rate'] == 1.0) and S_err > 0, 'rate control: the rate is 1 at every record')
core = json.load(open(os.path.join(d, 'rate', 'summary.json')))['quantities']['tau']
tolerance = 3.0 * np.hypot(S_err, core['error'])
T.check(abs(core['value'] - S) <= tolerance,
        'rate control: the core\'s shear stress (summary tau, from the stresslets) is the mean wall stress %.3f +- %.3f: '
        '%.3f +- %.3f, within 3 sigma = %.3f' % (S, S_err, core['value'], core['error'], tolerance))

T.run(T.write_deck(d, 'stress.nml', DECK.format(shear="control = 'stress', stress = %.15g" % S, steps=1200,
                                                out='stress')), d)
s = T.series(os.path.join(d, 'stress'))
rate = s['shear/rate']
miss = np.max(np.abs(s['shear/stress'] - S)) / S
T.check(miss < 1e-12, 'the stress each step solved for is S = %.4f (largest relative miss %.1e)' % (S, miss))
miss = np.max(np.abs(wall_stress(s) - S)) / S
T.check(miss < 1e-12, 'the mean wall stress summed from the wall columns is S at every record (%.1e)' % miss)
w = protocols.wall_shear_stress(os.path.join(d, 'stress'))
miss = np.max(np.abs(w['sigma'] - wall_stress(s))) / S
T.check(miss < 1e-12 and np.array_equal(w['step'], s['step']),
        'fdsusp.protocols.wall_shear_stress sums the same (%.1e)' % miss)
miss = np.max(np.abs(np.diff(s['shear/strain']) - DT * rate[:-1]))
T.check(s['shear/strain'][0] == 0.0 and miss < 1e-12, 'the strain advances with the walls, dt rate_n (%.1e)' % miss)
f = s['wall_force_lubrication'][:, :, 0]
c = s['wall_force_contact'][:, :, 0]
T.check(np.any(s['contacts_wall'] > 0) and np.all(s['lubrication_walls'] > 0) and np.max(np.abs(f)) > 0
        and np.max(np.abs(c)) > 0, 'wall contacts and wall lubrication carry stress in the steps')
mean, err = block_mean(rate[s['step'] > DISCARD])
tolerance = 3.0 * np.hypot(err, S_err / S)
print('S = %.4f +- %.4f; stress control at S: mean rate %.4f +- %.4f (rate range %.3f .. %.3f)'
      % (S, S_err, mean, err, rate.min(), rate.max()))
T.check(abs(mean - 1.0) <= tolerance,
        'the mean rate under stress control gives back the rate 1: %.4f, |%.4f| <= 3 sigma = %.4f'
        % (mean, mean - 1.0, tolerance))

T.finish()

