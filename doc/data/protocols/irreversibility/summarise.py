"""Irreversibility under oscillatory shear (README.md here): the stroboscopic mean-square
displacement between cycles of each run (fdsusp.protocols.stroboscopic_msd) and the fraction of
spheres that moved farther than THRESHOLD, each run's state, and per phi the bracket of the
threshold gamma_c, into summary.json and doc/figures/irreversibility_ld.png.
    PYTHONPATH=python python3 doc/data/protocols/irreversibility/summarise.py [OUT]
OUT: out/protocols/irreversibility. The runs are the decks osc_p*_g*.nml here (phi, gamma_0 and the
number of cycles read from each deck); a deck not run (yet) is skipped.

The series' first record is at step series_every, not at the start: the displacements seen are
those over cycles 2, 3, ... of the run (msd_per_cycle[i]: over cycle i + 2).
States (after the run's last cycle; m = msd per cycle, f = fraction moved):
  reversible  f = 0 in every cycle (no sphere ever came back farther than THRESHOLD)
  absorbing   f > 0 in the first cycles, f = 0 in the last LAST cycles (it organised)
  decaying    f > 0 in the last LAST cycles, but their mean m < DECAY x that of the first LAST
              cycles: still active, still organising (or critical slowing down); never counted as
              absorbing
  active      f > 0 in the last LAST cycles and their mean m >= DECAY x that of the first LAST
Bracket per phi: gamma_lo = the largest gamma_0 reversible or absorbing, gamma_hi = the smallest
gamma_0 active (of several runs at one gamma_0, the one with the most cycles decides); decaying runs
are listed apart."""
import glob
import json
import os
import re
import sys

import numpy as np
from fdsusp import protocols

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, '..', '..', '..', '..'))
OUT = sys.argv[1] if len(sys.argv) > 1 else 'out/protocols/irreversibility'
BOX = [10.0, 10.0, 10.0]
THRESHOLD = 0.01    # [a]: twice the roughness; a sphere that came back closer than this is reversible
LAST = 3            # the cycles the early and late values average
DECAY = 0.25        # late / early msd below this: decaying, not active


def deck_values(path):
    """phi, gamma_0, cycles (steps dt / period) of a deck."""
    text = open(path).read()
    number = lambda key: float(re.search(key + r'\s*=\s*([0-9.eE+-]+)', text).group(1))
    phi, gamma_0, period = number('solid_fraction'), number('strain_amplitude'), number('period')
    cycles = int(round(number('steps') * number('dt') / period))
    return phi, gamma_0, cycles


def bracket(b):
    lo, hi = b['gamma_lo'], b['gamma_hi']
    text = ('%g < gamma_c' % lo if lo is not None else 'gamma_c') + (' <= %g' % hi if hi is not None else ' (no active run)')
    return text + ('; decaying at %s' % ', '.join('%g' % g for g in b['decaying']) if b['decaying'] else '')


def state(msd, moved):
    if np.all(moved == 0):
        return 'reversible'
    if np.all(moved[-LAST:] == 0):
        return 'absorbing'
    return 'decaying' if msd[-LAST:].mean() < DECAY * msd[:LAST].mean() else 'active'


def entry(phi, gamma_0, cycles, msd, moved, source):
    msd, moved = np.asarray(msd), np.asarray(moved)
    absorbed = [k for k in range(len(moved)) if np.all(moved[k:] == 0)]
    return {'phi': phi, 'gamma_0': gamma_0, 'cycles_asked': cycles, 'cycles': len(msd), 'source': source,
            'msd_per_cycle': [float(x) for x in msd], 'moved_per_cycle': [float(x) for x in moved],
            'msd_late': float(msd[-LAST:].mean()), 'moved_late': float(moved[-LAST:].mean()),
            'late_over_early': float(msd[-LAST:].mean() / msd[:LAST].mean()),
            'no_move_from_cycle': (absorbed[0] + 2) if absorbed else None, 'state': state(msd, moved)}


# a run whose output is gone (out/ is not kept) keeps the per-cycle values summary.json holds
try:
    kept = json.load(open(os.path.join(HERE, 'summary.json')))['runs']
except (OSError, ValueError, KeyError):
    kept = {}
result = {'cycle_numbering': 'msd_per_cycle[i], moved_per_cycle[i]: over cycle i + 2 of the run (between the ends of cycles '
                             'i + 1 and i + 2; the run\'s start is not a record, so cycle 1 is not seen); no_move_from_cycle: '
                             'the first cycle from which no sphere moved', 'threshold_a': THRESHOLD, 'late_cycles': LAST, 'decay_ratio': DECAY, 'runs': {}, 'phi': {}}
for deck in sorted(glob.glob(os.path.join(HERE, 'osc_p*_g*.nml'))):
    name = os.path.basename(deck)[:-4]
    phi, gamma_0, cycles = deck_values(deck)
    try:
        m = protocols.stroboscopic_msd(os.path.join(OUT, name), BOX, threshold=THRESHOLD)
    except (OSError, KeyError, protocols.NoProtocol) as err:     # not run, or fewer than two cycles yet
        if name in kept:
            result['runs'][name] = entry(phi, gamma_0, cycles, kept[name]['msd_per_cycle'],
                                         kept[name]['moved_per_cycle'], kept[name].get('source', 'summary.json (run 2026-11-28, main at 9212335; output not kept)'))
            print('%s: from summary.json (%s)' % (name, err))
        else:
            print('%s: skipped (%s)' % (name, err))
        continue
    result['runs'][name] = entry(phi, gamma_0, cycles, m['msd'], m['moved'], os.path.join(OUT, name))

for phi in sorted({r['phi'] for r in result['runs'].values()}):
    runs = {n: r for n, r in result['runs'].items() if r['phi'] == phi}
    by_gamma = {}
    for n, r in sorted(runs.items(), key=lambda x: x[1]['cycles']):    # the longest run decides
        by_gamma[r['gamma_0']] = r['state']
    quiet = [g for g, s in by_gamma.items() if s in ('reversible', 'absorbing')]
    active = [g for g, s in by_gamma.items() if s == 'active']
    result['phi']['%g' % phi] = {'runs': sorted(runs, key=lambda n: (runs[n]['gamma_0'], runs[n]['cycles'])),
                                 'gamma_lo': max(quiet) if quiet else None,
                                 'gamma_hi': min(active) if active else None,
                                 'decaying': sorted(g for g, s in by_gamma.items() if s == 'decaying')}
json.dump(result, open(os.path.join(HERE, 'summary.json'), 'w'), indent=1)

for phi, b in result['phi'].items():
    print('phi %s: %s' % (phi, bracket(b)))
    for name in b['runs']:
        r = result['runs'][name]
        k5 = min(4, r['cycles'] - 1)     # cycle 6
        print('  %-16s gamma_0 %-4g cycles %2d  msd (cycle 2 -> 6 -> last) %.2g -> %.2g -> %.2g a^2  moved %.2f -> %.2f -> %.2f  '
              'late/early %.2g  %s' % (name, r['gamma_0'], r['cycles'], r['msd_per_cycle'][0], r['msd_per_cycle'][k5],
                                       r['msd_per_cycle'][-1], r['moved_per_cycle'][0], r['moved_per_cycle'][k5],
                                       r['moved_per_cycle'][-1], r['late_over_early'], r['state'])
              + ('' if r['no_move_from_cycle'] is None else ' (none moved from cycle %d)' % r['no_move_from_cycle']))

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt
phis = list(result['phi'])
fig, axes = plt.subplots(2, max(1, len(phis)), figsize=(4.2 * max(1, len(phis)), 7), squeeze=False)
for j, phi in enumerate(phis):
    top, bottom = axes[0, j], axes[1, j]
    for name in result['phi'][phi]['runs']:
        r = result['runs'][name]
        if any(q['phi'] == r['phi'] and q['gamma_0'] == r['gamma_0'] and q['cycles'] > r['cycles']
               for q in result['runs'].values()):
            continue        # a longer run at this gamma_0 holds these cycles too (it was continued from this one or redid it)
        k = np.arange(2, r['cycles'] + 2)    # cycle i + 2 of the run (its start is not a record)
        label = 'gamma_0 = %g%s: %s' % (r['gamma_0'], '' if r['cycles_asked'] == 10 else ' (%d cycles)' % r['cycles_asked'],
                                        r['state'])
        top.semilogy(k, np.maximum(r['msd_per_cycle'], 1e-12), 'o-', ms=3, label=label)
        bottom.plot(k, r['moved_per_cycle'], 'o-', ms=3, label=label)
    b = result['phi'][phi]
    top.set_title('phi %s: %s' % (phi, bracket(b)), fontsize=9)
    top.set_ylabel(r'stroboscopic $\langle|\Delta x|^2\rangle$ per cycle [$a^2$]')
    bottom.set_ylabel('fraction of spheres moved > %g a' % THRESHOLD)
    bottom.set_xlabel('cycle')
    for ax in (top, bottom):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6)
fig.suptitle('LD, Lees-Edwards cube 10a, rough frictionless spheres, seed 3: oscillatory shear, T = 6.4 gamma_0',
             fontsize=9)
fig.tight_layout()
fig.savefig(os.path.join(ROOT, 'doc', 'figures', 'irreversibility_ld.png'), dpi=100)
