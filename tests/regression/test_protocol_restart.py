"""Invariant: a protocol restarts exactly (doc/INPUT.md "&shear"): the checkpoint holds its state
(shear_protocol_state: t_n, gamma(t_n), the accumulated |strain|, the direction, the reversals, the
last rate), so N steps in one run equal N/2 steps, a checkpoint, a restart and N/2 steps: every
dataset and attribute of the two final checkpoints and of the two series.h5 (wall_time excepted)
agree bitwise (rtol 0: the continued run repeats the same arithmetic, as test_restart asks of
steady runs). Cases, each stopped in the middle of what the protocol does:
- an oscillation in lubrication dynamics (49 rough frictional spheres, phi 0.4, Lees-Edwards,
  contacts, &rheology; gamma_0 = 0.2, T = 251.3 steps), 200 steps against 100 + 100: the restart
  falls at 0.4 period, with contacts under load;
- a reversal in lubrication dynamics between walls (G = 60 steps' strain), 150 against 75 + 75:
  the reversals at steps 60 and 120 lie on either side of the restart;
- an oscillation of the pure fluid in the DNS on 2 ranks (T = 40 steps), 60 against 30 + 30;
- stress control (control = 'stress') in lubrication dynamics (the oscillation's scene at stress 8),
  200 against 100 + 100: the rate the restarted step solves for starts its solves from the
  checkpoint's velocities and rate, as the uninterrupted step does; and of the pure fluid in the
  DNS on 2 ranks (stress 2.5 from rest), 60 against 30 + 30: the unit wall-speed response is made
  again at the restart, the same; and of the DNS with 31 rough frictional spheres between walls
  (phi 0.25, a/Delta = 2, eps_r 0.05, contacts under load) on 2 ranks, stress 3, 60 against 30 + 30, and
  its stress reversed every 0.05 strain (~17 steps) on 1 rank, 100 against 50 + 50: the step's two
  particle solves start from the checkpoint's velocities and rate, Lambda and the fluid are the
  checkpoint's (doc/METHOD.md §7.4);
- a reversal of the stress (8, G = 0.3) and an oscillation of the stress (amplitude 8, T = 150
  steps) in lubrication dynamics, 200 against 100 + 100: the restart between two flips of the
  stress, and at 2/3 of a period;
- steps of the stress by time in lubrication dynamics (8, 12, 6 from t = 0, 0.3, 0.7: steps 61
  and 141), 200 against 100 + 100: the level of the last step is in the checkpoint (as the
  reversals are), so the restarted step sees no spurious jump.
A branch (-branch) starts the deck's protocol afresh from the checkpoint's configuration: after a
steady pre-shear of 100 steps in lubrication dynamics (Lees-Edwards), a reversal every 0.25 strain
flips at the steps 50, 100, 150 after the branch, and both it and an oscillation continue the
boundary offset from the checkpoint's (its next step's strain added, to 1e-12 a), the oscillation's
strain starting from the strain the pre-shear reached (offset / Ly).
A few seconds on 2 cores."""
import math
import os
import numpy as np
import fdsusp_testlib as T

OSC = """&domain box = 8.0, 8.0, 8.0, y_boundary = 'lees-edwards' /
&shear protocol = 'oscillatory', strain_amplitude = 0.2, period = 1.2566370614359172 /
&fluid model = 'none' /
&time dt = 5.0e-3, steps = {steps} /
&output directory = 'out', progress_every = 1000 /
&particles solid_fraction = 0.4, seed = 1 /
&contact roughness = 5.0e-3, friction = 0.5 /
&rheology discard_strain = 0.0, average_strain = 0.95, blocks = 2 /
"""
REV = """&domain box = 8.0, 8.0, 8.0, y_boundary = 'walls' /
&shear rate = -1.0, protocol = 'reversal', reversal_strain = 0.3 /
&fluid model = 'none' /
&time dt = 5.0e-3, steps = {steps} /
&output directory = 'out', progress_every = 1000 /
&particles solid_fraction = 0.35, seed = 4 /
&contact roughness = 5.0e-3, friction = 0.5 /
&rheology discard_strain = 0.0, average_strain = 0.7, blocks = 2 /
"""
STEADY = """&domain box = 8.0, 8.0, 8.0, y_boundary = 'lees-edwards' /
&shear {shear} /
&fluid model = 'none' /
&time dt = 5.0e-3, steps = {steps} /
&output directory = 'out', progress_every = 1000 /
&particles solid_fraction = 0.35, seed = 5 /
&contact roughness = 5.0e-3, friction = 0.5 /
"""
STRESS = """&domain box = 8.0, 8.0, 8.0, y_boundary = 'lees-edwards' /
&shear control = 'stress', stress = 8.0 /
&fluid model = 'none' /
&time dt = 5.0e-3, steps = {steps} /
&output directory = 'out', progress_every = 1000 /
&particles solid_fraction = 0.4, seed = 1 /
&contact roughness = 5.0e-3, friction = 0.5 /
&rheology discard_strain = 0.0, average_strain = 0.95, blocks = 2 /
"""
STEPS = STRESS.replace("stress = 8.0", "protocol = 'steps', step_by = 'time', levels = 3, step_at = 0.0, 0.3, 0.7, "
                       "step_level = 8.0, 12.0, 6.0")
STRESS_REVERSAL = STRESS.replace("stress = 8.0", "stress = 8.0, protocol = 'reversal', reversal_strain = 0.3")
STRESS_OSCILLATION = STRESS.replace("stress = 8.0", "stress = 8.0, protocol = 'oscillatory', period = 0.75")
STRESS_DNS = """&domain box = 8.0, 8.0, 8.0, cells_per_radius = 2 /
&shear control = 'stress', stress = 3.0 /
&fluid reynolds = 0.01, viscous_theta = 1.0, initial_flow = 'shear' /
&time dt = 2.0e-3, steps = {steps} /
&output directory = 'out', progress_every = 1000 /
&particles solid_fraction = 0.25, seed = 1 /
&contact roughness = 0.05, friction = 0.5 /
&lubrication model = 'simple' /
"""
STRESS_DNS_REVERSAL = STRESS_DNS.replace("stress = 3.0", "stress = 3.0, protocol = 'reversal', reversal_strain = 0.05")
STRESS_FLUID = """&domain box = 4.0, 4.0, 4.0, cells_per_radius = 2 /
&shear control = 'stress', stress = 2.5 /
&fluid reynolds = 0.01, viscous_theta = 1.0 /
&time dt = 1.0e-2, steps = {steps} /
&output directory = 'out', progress_every = 1000 /
"""
FLUID = """&domain box = 4.0, 4.0, 4.0, cells_per_radius = 2 /
&shear protocol = 'oscillatory', strain_amplitude = 0.5, period = 0.4 /
&fluid reynolds = 0.01, initial_flow = 'shear' /
&time dt = 1.0e-2, steps = {steps} /
&output directory = 'out', progress_every = 1000 /
"""


# Each case: the straight run and the first half of the split run, all independent of one
# another, are run together (T.run_many: two ranks at a time), then the second halves; the
# comparisons follow, each of a run with its own split twin.
CASES = [('oscillation', OSC, 200, 1), ('reversal', REV, 150, 1), ('fluid', FLUID, 60, T.RANKS),
         ('stress', STRESS, 200, 1), ('stress_steps', STEPS, 200, 1), ('stress_reversal', STRESS_REVERSAL, 200, 1),
         ('stress_oscillation', STRESS_OSCILLATION, 200, 1), ('stress_fluid', STRESS_FLUID, 60, T.RANKS),
         ('stress_dns', STRESS_DNS, 60, T.RANKS), ('stress_dns_reversal', STRESS_DNS_REVERSAL, 100, 1)]
work = lambda name: os.path.join(T.ROOT, 'build', 'test-work', name)   # a directory T.scratch made
first, second = [], []
for name, deck, steps, ranks in CASES:
    a = T.scratch('protocol_restart_%s_straight' % name)
    first.append(dict(deck=T.write_deck(a, 'd.nml', deck.format(steps=steps)), cwd=a, np_ranks=ranks))
    b = T.scratch('protocol_restart_%s_split' % name)
    first.append(dict(deck=T.write_deck(b, 'half.nml', deck.format(steps=steps // 2)), cwd=b, np_ranks=ranks))
# the branch cases' steady pre-shear (below)
b = T.scratch('protocol_restart_branch')
first.append(dict(deck=T.write_deck(b, 'steady.nml', STEADY.format(steps=100, shear='rate = 1.0')), cwd=b))
first.sort(key=lambda r: -r.get('np_ranks', 1))     # the parallel runs first, while nothing else runs
T.run_many(first)
for name, deck, steps, ranks in CASES:
    b = work('protocol_restart_%s_split' % name)
    second.append(dict(deck=T.write_deck(b, 'd.nml', deck.format(steps=steps)), cwd=b, np_ranks=ranks,
                       args=['-restart', 'out/checkpoint.h5']))
BRANCHES = (('reversal', "rate = 1.0, protocol = 'reversal', reversal_strain = 0.25", 260),
            ('oscillation', "protocol = 'oscillatory', strain_amplitude = 0.05, period = 0.3", 160))
b = work('protocol_restart_branch')
for name, shear, steps in BRANCHES:
    second.append(dict(deck=T.write_deck(b, name + '.nml', STEADY.format(steps=steps, shear=shear).replace(
        "directory = 'out'", "directory = '%s'" % name)), cwd=b, args=['-branch', 'out/checkpoint.h5']))
branch_logs = [out for _, out, _ in T.run_many(second)[len(CASES):]]


def split(name, steps):
    a = work('protocol_restart_%s_straight' % name)
    b = work('protocol_restart_%s_split' % name)
    T.compare_h5(os.path.join(a, 'out', 'checkpoint.h5'), os.path.join(b, 'out', 'checkpoint.h5'),
                 '%s: %d steps against %d + restart + %d, checkpoint' % (name, steps, steps // 2, steps // 2), rtol=0)
    T.compare_h5(os.path.join(a, 'out', 'series.h5'), os.path.join(b, 'out', 'series.h5'),
                 '%s: series' % name, rtol=0, skip=('wall_time',))
    s = T.series(os.path.join(b, 'out'))
    T.check(np.array_equal(s['step'], np.arange(1, steps + 1)), '%s: series steps 1..%d, each once' % (name, steps))
    return s


s = split('oscillation', 200)
T.check(np.any(s['core/stress_contact'][:, 3] != 0), 'oscillation: contacts carry stress (their springs restart too)')
s = split('reversal', 150)
flips = s['step'][1:][np.sign(s['shear/rate'][1:]) != np.sign(s['shear/rate'][:-1])]
T.check(list(flips) == [61, 121], 'reversal: the rate flips at steps 61 and 121, across the restart: %s' % list(flips))
split('fluid', 60)
s = split('stress', 200)
T.check(np.all(np.abs(s['shear/stress'] - 8.0) < 1e-12) and np.ptp(s['shear/rate']) > 0,
        'stress control: the stress is 8 at every record, the rate varies (%.3f .. %.3f)'
        % (s['shear/rate'].min(), s['shear/rate'].max()))
s = split('stress_steps', 200)
T.check(list(s['step'][1:][np.abs(np.diff(s['shear/stress'])) > 1]) == [61, 141],
        'stress steps: the stress changes at steps 61 and 141, on either side of the restart')
s = split('stress_reversal', 200)
flips = s['step'][1:][np.sign(s['shear/stress'][1:]) != np.sign(s['shear/stress'][:-1])]
T.check(len(flips) >= 2 and flips[0] < 101 < flips[-1] and np.all(np.abs(np.abs(s['shear/stress']) - 8.0) < 1e-12),
        'stress reversal: the stress is +-8 and flips at steps %s, on either side of the restart' % list(flips))
s = split('stress_oscillation', 200)
T.check(np.all(np.abs(s['shear/stress'] - 8.0 * np.sin(2 * np.pi * (s['step'] - 1) * 5.0e-3 / 0.75)) < 1e-11),
        'stress oscillation: the stress is 8 sin(2 pi t_n/T) at every record (the restart at 2/3 of a period)')
s = split('stress_fluid', 60)
T.check(np.all(np.abs(s['shear/stress'] - 2.5) < 1e-12), 'stress control of the fluid alone: the stress is 2.5 at every record')
s = split('stress_dns', 60)
T.check(np.all(np.abs(s['shear/stress'] - 3.0) < 1e-12) and np.any(s['contacts_pair'] > 0),
        'stress control of the DNS with spheres: the wall stress is 3 at every record, contacts in the steps')
s = split('stress_dns_reversal', 100)
flips = s['step'][1:][np.sign(s['shear/stress'][1:]) != np.sign(s['shear/stress'][:-1])]
T.check(len(flips) >= 2 and flips[0] < 51 < flips[-1] and np.all(np.abs(np.abs(s['shear/stress']) - 3.0) < 1e-12),
        'stress reversal in the DNS with spheres: the wall stress is +-3 and flips at steps %s, on either side of '
        'the restart' % list(flips))

# a branch starts the deck's protocol afresh from the configuration reached: a steady pre-shear of
# 100 steps (Lees-Edwards), then a reversal every 50 steps' strain, and an oscillation (run above)
b = work('protocol_restart_branch')
pre = T.series(os.path.join(b, 'out'))
for (name, shear, steps), out in zip(BRANCHES, branch_logs):
    T.check("&shear protocol '%s' starts afresh" % ('reversal' if name == 'reversal' else 'oscillatory') in out
            and "&shear protocol changed from 'steady'" in out, '%s branch: the log names the change of protocol' % name)
    s = T.series(os.path.join(b, name))
    offset = s['lees_edwards_offset']
    first = s['step'][0]
    if name == 'reversal':
        flips = s['step'][1:][np.sign(s['shear/rate'][1:]) != np.sign(s['shear/rate'][:-1])]
        T.check(first == 101 and list(flips) == [151, 201, 251] and s['shear/rate'][0] == 1.0,
                'reversal branch: from step 101, flips at 151, 201, 251 (50 steps after the branch, then every 50): %s'
                % list(flips))
        expected = (pre['lees_edwards_offset'][-1] + 1.0 * 8.0 * 5.0e-3) % 8.0
    else:
        expected = (pre['lees_edwards_offset'][-1] + 0.05 * math.sin(2 * math.pi * 5.0e-3 / 0.3) * 8.0) % 8.0
        T.check(abs(s['shear/strain'][0] - pre['lees_edwards_offset'][-1] / 8.0) < 1e-12,
                'oscillation branch: the strain starts where the pre-shear left the boundary (offset / Ly)')
    T.check(abs(offset[0] - expected) < 1e-12,
            '%s branch: the boundary offset continues from the checkpoint\'s (%.12f, expected %.12f)'
            % (name, offset[0], expected))
T.finish()
