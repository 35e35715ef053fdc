"""Invariant: the steady protocol of &shear is today's run (doc/INPUT.md "&shear"): a deck giving
its rate as `&shear rate = R` (protocol 'steady', the default) and the same deck with the older
`&domain shear_rate = R` write the same series.h5 and the same checkpoint, bitwise (rtol 0: the
same arithmetic, since a steady protocol changes nothing in the step; wall_time and the recorded
output directory excepted). Checked in lubrication dynamics across Lees-Edwards boundaries at a
negative rate (rough frictional contacts, lubrication, &rheology; 60 steps) and between walls
(30 steps), and in a small DNS between walls (two free rough spheres with lubrication, a/Delta 4,
10 steps on 2 ranks). The series also holds the protocol's columns: shear/rate = R at every
record and shear/strain = R t_n (to 1e-12: a sum of R dt)."""
import os
import numpy as np
import fdsusp_testlib as T

LD = """&domain box = 8.0, 8.0, 8.0, y_boundary = '{boundary}'{old} /
{new}&fluid model = 'none' /
&time dt = 5.0e-3, steps = {steps} /
&output directory = 'out', progress_every = 1000 /
&particles solid_fraction = 0.3, seed = 2 /
&contact roughness = 5.0e-3, friction = 0.5 /
&rheology discard_strain = 0.05, average_strain = 0.2, blocks = 2 /
"""
DNS = """&domain box = 6.0, 6.0, 6.0, cells_per_radius = 4{old} /
{new}&fluid reynolds = 0.01, initial_flow = 'shear' /
&time dt = 1.0e-3, steps = 10 /
&output directory = 'out', progress_every = 1000 /
&particles number = 2, position(:,1) = 2.0, 3.0, 3.0, position(:,2) = 4.1, 3.3, 3.0 /
&contact roughness = 5.0e-3 /
&lubrication model = 'full', outer_cutoff = 0.5 /
"""


def pair(name, deck, rate, ranks=1):
    """Run DECK with the rate under its old and its new name; compare."""
    runs = {}
    for how in ('old', 'new'):
        d = T.scratch('protocol_steady_%s_%s' % (name.replace(' ', '_'), how))
        text = deck.format(old=', shear_rate = %r' % rate if how == 'old' else '',
                           new="&shear rate = %r, protocol = 'steady' /\n" % rate if how == 'new' else '')
        T.run(T.write_deck(d, 'd.nml', text), d, np_ranks=ranks)
        runs[how] = d
    out = {h: os.path.join(runs[h], 'out') for h in runs}
    T.compare_h5(os.path.join(out['old'], 'series.h5'), os.path.join(out['new'], 'series.h5'),
                 '%s: series of &domain shear_rate and &shear rate' % name, rtol=0, skip=('wall_time',))
    T.compare_h5(os.path.join(out['old'], 'checkpoint.h5'), os.path.join(out['new'], 'checkpoint.h5'),
                 '%s: checkpoints of &domain shear_rate and &shear rate' % name, rtol=0)
    s = T.series(out['new'])
    dt = 5.0e-3 if 'DNS' not in name else 1.0e-3
    T.check(np.all(s['shear/rate'] == rate), '%s: shear/rate = %g at every record' % (name, rate))
    err = np.max(np.abs(s['shear/strain'] - rate * (s['time'] - dt)))
    T.check(err < 1e-12, '%s: shear/strain = rate t_n (%.1e < 1e-12)' % (name, err))


pair('LD Lees-Edwards', LD.replace('{boundary}', 'lees-edwards').replace('{steps}', '60'), -0.75)
pair('LD walls', LD.replace('{boundary}', 'walls').replace('{steps}', '30'), 1.0)
pair('DNS walls', DNS, 1.0, ranks=T.RANKS)
T.finish()
