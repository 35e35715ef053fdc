"""Invariant: in lubrication dynamics (&fluid model = 'none') a free pair of UNEQUAL spheres in
simple shear is the two-sphere problem bin/pairtraj integrates with &pair size_ratio: each
sphere's one-body resistance with its own radius plus the sized pair blocks (lambda = a_2/a_1, gap
xi = 2r/(a_1 + a_2) - 2) minus both one-body parts is the exact two-sphere resistance of the pair
(doc/LUBRICATION.md "Spheres of several sizes"), and the Hertz-Coulomb contact is the same law with
the pair's stiffness (doc/CONTACT.md "Spheres of several sizes"). As tests/physics/test_ld_pair.py:
sphere 1 of radius 1 (the unit), sphere 2 of radius lambda = 1.4 and 2, relative position
(-6, 0.5, 0) at the start, integrated until x = +6; smooth (eps_r = 0, no contacts) and rough
frictional (eps_r = 1e-2, eps_bar = 0.05, mu_d = 0.3, input/pair_eps1e-2_mu03.nml). Compared: the
offset y where x crosses +6 and the passage time (1e-3 relative), and the whole path y(x) (max
|y_fdsusp(x) - y_pairtraj(x)| <= 1e-3 a). &lubrication outer_cutoff = 6 (in xi) holds the whole
path inside the untapered range (start xi = 3.02 at lambda 1.4, 2.01 at lambda 2; the taper begins
at 4.2), in a Lees-Edwards box of 36a (the search needs 2 (2 a_max + 6 a_max + skin) = 32.4a).
Measured differences (doc/VALIDATION.md §8): offsets 1.0e-5 .. 2.4e-5 relative, passage times
3e-6 .. 7e-6, paths 5e-6 .. 3.5e-5 a, the size of the equal pair's (test_ld_pair: 1e-5, 2e-5).
They are not fdsusp's step error alone (halving dt = 2e-3 moves the rough lambda = 2 offset by
2.5e-6 only): the two codes differ in their contact integration (fdsusp's implicit spring update
per step against pairtraj's continuous one) and in fdsusp's inner cut-off of the gap. 1e-3 leaves
a margin of 40; without the pair hydrodynamics the offset is off by 144 % (the control)."""
import os
import numpy as np
import fdsusp_testlib as T
import pairtraj_lib as P

DECK = """&domain box = 36, 36, 36, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 2e-3, steps = {steps} /
&output directory = 'out', progress_every = 100000, series_every = 5 /
&particles radius = 1.0, {lam}, number_share = 0.5, 0.5, position_file = 'pair.h5' /
&lubrication model = 'full', outer_cutoff = 6 /
"""
CONTACT = "&contact roughness = 1e-2, eps_bar = 0.05, friction = 0.3 /\n"


def pair_file(d, lam):
    with T.h5py.File(os.path.join(d, 'pair.h5'), 'w') as f:
        f.create_dataset('particles/position', data=np.array([[20.0, 17.75, 18.0], [14.0, 18.25, 18.0]]))
        f.create_dataset('particles/radius', data=np.array([1.0, lam]))


def path(outdir):
    """relative position of sphere 2 from sphere 1 (minimum image) and time, per record."""
    s = T.series(outdir)
    r = s['particles/position'][:, 1, :] - s['particles/position'][:, 0, :]
    r -= 36.0 * np.round(r / 36.0)
    return r, s['time']


def crossing(r, t):
    k = int(np.argmax(r[:, 0] >= 6.0))
    if r[k, 0] < 6.0:
        return float('nan'), float('nan')
    w = (6.0 - r[k - 1, 0]) / (r[k, 0] - r[k - 1, 0])
    return r[k - 1, 1] + w * (r[k, 1] - r[k - 1, 1]), t[k - 1] + w * (t[k] - t[k - 1])


def prepare(case, lam, steps, extra, model='full'):
    """The run of a case in a directory of its own, for T.run_many."""
    d = T.scratch('ld_pair_unequal_%s_%s_%s' % (case, lam, model))
    pair_file(d, lam)
    return dict(deck=T.write_deck(d, 'p.nml', DECK.format(steps=steps, lam=lam) .replace("'full'", "'%s'" % model) + extra),
                cwd=d)


# pairtraj for every case, then the five runs (the four cases and the control), which are
# independent, together, two at a time; the checks in the cases' order
CASES = [(case, deck, extra, lam) for case, deck, extra in (('smooth', 'pair_eps0', ''), ('rough', 'pair_eps1e-2_mu03', CONTACT))
         for lam in (1.4, 2.0)]
refs, runs = {}, []
for case, deck, extra, lam in CASES:
    refs[case, lam] = P.run_deck(deck, tag='ld_uneq_%s_%s' % (deck, lam), dt_out='0.01', x_end='6.0\n  size_ratio = %s' % lam)
    steps = int(refs[case, lam][0]['final_t'] / 2e-3) + 200
    runs.append(prepare(case, lam, steps, extra))
    if case == 'rough' and lam == 2.0:
        # control: without the pair hydrodynamics the offset is far off
        control = prepare(case, lam, steps, extra, model='none')
T.run_many(runs + [control])

for (case, deck, extra, lam), one in zip(CASES, runs):
    ref, rows = refs[case, lam]
    r, t = path(os.path.join(one['cwd'], 'out'))
    y, tc = crossing(r, t)
    ey = abs(y - ref['final_y']) / abs(ref['final_y'])
    et = abs(tc - ref['final_t']) / ref['final_t']
    T.check(ey <= 1e-3, '%s lambda %.1f: final offset y = %.6f a, pairtraj %.6f a, difference %.1e (<= 1e-3)'
            % (case, lam, y, ref['final_y'], ey))
    T.check(et <= 1e-3, '%s lambda %.1f: passage time %.4f, pairtraj %.4f, difference %.1e (<= 1e-3)'
            % (case, lam, tc, ref['final_t'], et))
    # the path y(x) on pairtraj's records inside the run's range
    xs = np.array([q['x'] for q in rows])
    ys = np.array([q['y'] for q in rows])
    keep = r[:, 0] < 6.0
    yp = np.interp(r[keep, 0], xs, ys)
    dev = float(np.max(np.abs(r[keep, 1] - yp)))
    T.check(dev <= 1e-3, '%s lambda %.1f: path max |y - y_pairtraj| at the same x = %.1e a (<= 1e-3 a)'
            % (case, lam, dev))
    if case == 'rough' and lam == 2.0:
        r0, t0 = path(os.path.join(control['cwd'], 'out'))
        y0, _ = crossing(r0, t0)
        T.check(not abs(y0 / ref['final_y'] - 1) <= 0.01,
                'control: one-body drag alone gives y = %.4f a, %.0f %% from pairtraj'
                % (y0, 100 * abs(y0 / ref['final_y'] - 1)))
T.finish()
