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
- an oscillation of the pure fluid in the DNS on 2 ranks (T = 40 steps), 60 against 30 + 30.
A few seconds on 2 cores."""
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
FLUID = """&domain box = 4.0, 4.0, 4.0, cells_per_radius = 2 /
&shear protocol = 'oscillatory', strain_amplitude = 0.5, period = 0.4 /
&fluid reynolds = 0.01, initial_flow = 'shear' /
&time dt = 1.0e-2, steps = {steps} /
&output directory = 'out', progress_every = 1000 /
"""


def split(name, deck, steps, ranks=1):
    a = T.scratch('protocol_restart_%s_straight' % name)
    T.run(T.write_deck(a, 'd.nml', deck.format(steps=steps)), a, np_ranks=ranks)
    b = T.scratch('protocol_restart_%s_split' % name)
    T.run(T.write_deck(b, 'half.nml', deck.format(steps=steps // 2)), b, np_ranks=ranks)
    T.run(T.write_deck(b, 'd.nml', deck.format(steps=steps)), b, np_ranks=ranks,
          args=['-restart', 'out/checkpoint.h5'])
    T.compare_h5(os.path.join(a, 'out', 'checkpoint.h5'), os.path.join(b, 'out', 'checkpoint.h5'),
                 '%s: %d steps against %d + restart + %d, checkpoint' % (name, steps, steps // 2, steps // 2), rtol=0)
    T.compare_h5(os.path.join(a, 'out', 'series.h5'), os.path.join(b, 'out', 'series.h5'),
                 '%s: series' % name, rtol=0, skip=('wall_time',))
    s = T.series(os.path.join(b, 'out'))
    T.check(np.array_equal(s['step'], np.arange(1, steps + 1)), '%s: series steps 1..%d, each once' % (name, steps))
    return s


s = split('oscillation', OSC, 200)
T.check(np.any(s['core/stress_contact'][:, 3] != 0), 'oscillation: contacts carry stress (their springs restart too)')
s = split('reversal', REV, 150)
flips = s['step'][1:][np.sign(s['shear/rate'][1:]) != np.sign(s['shear/rate'][:-1])]
T.check(list(flips) == [61, 121], 'reversal: the rate flips at steps 61 and 121, across the restart: %s' % list(flips))
split('fluid', FLUID, 60, ranks=2)
T.finish()
