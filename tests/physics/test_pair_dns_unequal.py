"""Invariant: two free spheres of radii 1 and 2 in simple shear, resolved by the DNS (fictitious
domain with each sphere's radius, the full lubrication correction of the mixture's tables:
resolved_a4_ratio2.h5 for the pair, Hertz contacts on the roughness-shifted overlap with the pair's
stiffness), follow the relative trajectory of the exact two-sphere model bin/pairtraj with &pair
size_ratio = 2 (Jeffrey & Onishi's resistance of unequal spheres in unbounded Stokes flow, the same
contact law; its unequal pair is checked against lubrication dynamics to 2e-5 in
test_ld_pair_unequal). The paper's pair test (test_pair_dns) with an unequal pair (issue 44 item 5).

Set-up: cell 13a x 16a x 13a with walls in y (the lubrication search needs periodic lengths of
2 (2 + outer_cutoff) a2 + 2 skin = 12.4a), small sphere at a/Delta = 4 (the large one at 8),
relative start r = (-4a, 0.5a, 0) (gap xi = 0.69), Re = 0.01, dt = 1.25e-3, rough spheres eps_r =
1e-2, eps_bar = 0.1 in both codes, mu_d = 0, until x = 0 in make check (past the closest approach
and the contact) and x = +4a, the whole passage, with --full; 2 ranks.
Measured on the way (a 14a-wide cell; doc/VALIDATION.md §4.6): the final offset 1.778a in a cell
10a high at dt = 2.5e-3 (pairtraj 1.392a: +28 %, the walls 3a from the large sphere), 1.486a at
16a high (+6.7 %), 1.449a at 16a and dt = 1.25e-3 (+4.1 %): the walls and the lag of close free
pairs (dt^2/(Re Delta^2) = 1e-2 at dt = 2.5e-3, 2.5 times the limit mod_fictitious_domain warns
at) are what the DNS adds.
Tolerances, as test_pair_dns's and for the same reasons: the offset y where the pair crosses
x = 0 (--full: x = 4a) within 5 % of pairtraj's (the issue's criterion for the pair test); the path |y_DNS -
y_pairtraj| <= 0.05 (a1 + a2)/2 at every x (the equal test's 0.05a with the pair's mean radius
for a: the walls and the periodic images perturb the relative velocity by O((a/L)^3), and the
pair's size sets both a and the length of the path around the large sphere); the closest surface
gap within 2 % of pairtraj's (both set by the Hertz overlap at the same force).
"""
import os
import sys

import numpy as np

import fdsusp_testlib as T
import pairtraj_lib as P

LAM, CELLS, DT, START, Y0, EPS_BAR = 2.0, 4, 1.25e-3, -4.0, 0.5, 0.1
MEAN_RADIUS = 0.5 * (1 + LAM)       # the pair's length scale (the equal test's a)
BOX = (13.0, 16.0, 13.0)
# make check follows the pair to x = 0, past its closest approach and contact (3.5 min on 2 busy
# cores); --full to x = +4, the whole passage (7 min)
X_END = -START if '--full' in sys.argv else 0.0
summary, rows = P.run_deck('pair_eps1e-2', tag='dns_unequal', start='%r, %r, 0.0' % (START, Y0),
                           x_end='%r\n  size_ratio = %r' % (X_END, LAM), eps_bar=repr(EPS_BAR), dt_out='0.01')
# the DNS runs for STEPS_FACTOR times pairtraj's time to x = X_END and is compared up to where its
# pair crosses it (it crossed at 0.998 of pairtraj's time to x = 0 on 2026-11-29); a pair that has not
# crossed by then is continued from the final checkpoint (restarts are exact) by 10 % of that time
STEPS_FACTOR = 1.03
c = np.array(BOX) / 2
x1 = c - 0.5 * np.array([START, Y0, 0.0])
x2 = c + 0.5 * np.array([START, Y0, 0.0])


def deck(steps):
    return f"""&domain box = {BOX[0]}, {BOX[1]}, {BOX[2]}, cells_per_radius = {CELLS}, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, viscous_theta = 0.5, initial_flow = 'shear' /
&time dt = {DT}, steps = {steps} /
&output directory = 'out', progress_every = {max(1, steps // 10)}, series_every = 16 /
&particles radius = 1.0, {LAM}, number = 2, species = 1, 2,
  position(:,1) = {x1[0]!r}, {x1[1]!r}, {x1[2]!r}, position(:,2) = {x2[0]!r}, {x2[1]!r}, {x2[2]!r} /
&lubrication model = 'full' /
&contact roughness = 1.0e-2, eps_bar = {EPS_BAR}, friction = 0.0 /
"""


def relative_positions():
    s = T.series(os.path.join(d, 'out'))
    r = s['particles/position'][:, 1, :] - s['particles/position'][:, 0, :]
    r[:, [0, 2]] -= np.array(BOX)[[0, 2]] * np.round(r[:, [0, 2]] / np.array(BOX)[[0, 2]])
    return r


steps = int(STEPS_FACTOR * summary['final_t'] / DT)
d = T.scratch('pair_dns_unequal')
T.run(T.write_deck(d, 'pair.nml', deck(steps)), d, np_ranks=T.RANKS, timeout=3600)
r = relative_positions()
for _ in range(2):
    if r[:, 0].max() >= X_END:
        break
    more = steps + int(np.ceil(0.1 * summary['final_t'] / DT))
    print('not across x = %g by step %d; continued to step %d' % (X_END, steps, more))
    steps = more
    T.run(T.write_deck(d, 'pair.nml', deck(steps)), d, np_ranks=T.RANKS, timeout=3600,
          args=['-restart', 'out/checkpoint.h5'])
    r = relative_positions()
k = int(np.argmax(r[:, 0] >= X_END))
T.check(r[k, 0] >= X_END, 'the pair crosses x = %g a within the run (reached %.3f)' % (X_END, r[:, 0].max()))
if r[k, 0] >= X_END:
    w = (X_END - r[k - 1, 0]) / (r[k, 0] - r[k - 1, 0])
    y_end = r[k - 1, 1] + w * (r[k, 1] - r[k - 1, 1])
    err = abs(y_end - summary['final_y']) / abs(summary['final_y'])
    T.check(err <= 0.05, 'offset y = %.4f a where x = %g a, pairtraj %.4f a: %.2f %% (<= 5 %%)'
            % (y_end, X_END, summary['final_y'], 100 * err))
    keep = r[:, 0] < X_END
    xs = np.array([q['x'] for q in rows])
    ys = np.array([q['y'] for q in rows])
    dev = float(np.max(np.abs(r[keep, 1] - np.interp(r[keep, 0], xs, ys))))
    T.check(dev <= 0.05 * MEAN_RADIUS, 'path max |y_DNS - y_pairtraj| at the same x = %.4f a (<= 0.05 (a1 + a2)/2)'
            % dev)
    # the closest surface gap h = r - a1 - a2 (pairtraj's min_gap, in units of a1): both set by
    # the Hertz overlap at the same force
    h_dns = float(np.min(np.linalg.norm(r[keep], axis=1))) - (1 + LAM)
    T.check(abs(h_dns / summary['min_gap'] - 1) <= 0.02, 'closest surface gap %.5f a, pairtraj %.5f a (within 2 %%)'
            % (h_dns, summary['min_gap']))
T.finish()
