"""Irreversibility under oscillatory shear (README.md here): the stroboscopic mean-square
displacement between cycles of each run (fdsusp.protocols.stroboscopic_msd) and the fraction of
spheres that moved farther than THRESHOLD, into summary.json and doc/figures/irreversibility_ld.png.
    PYTHONPATH=python python3 doc/data/protocols/irreversibility/summarise.py [OUT]
OUT: out/protocols/irreversibility."""
import json
import os
import sys

import numpy as np
from fdsusp import protocols

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, '..', '..', '..', '..'))
OUT = sys.argv[1] if len(sys.argv) > 1 else 'out/protocols/irreversibility'
RUNS = {'osc_p30_g0.5': 0.5, 'osc_p30_g1': 1.0, 'osc_p30_g2': 2.0, 'osc_p30_g3': 3.0}
BOX = [10.0, 10.0, 10.0]
THRESHOLD = 0.01    # [a]: twice the roughness; a sphere that came back closer than this is reversible
LAST = 3            # the cycles the late values average


result = {'threshold_a': THRESHOLD, 'runs': {}}
for name, gamma_0 in RUNS.items():
    try:
        m = protocols.stroboscopic_msd(os.path.join(OUT, name), BOX, threshold=THRESHOLD)
    except (OSError, protocols.NoProtocol) as err:     # not run, or fewer than two cycles yet
        print('%s: skipped (%s)' % (name, err))
        continue
    msd, moved = np.asarray(m['msd']), np.asarray(m['moved'])
    result['runs'][name] = {'gamma_0': gamma_0, 'cycles': len(msd), 'msd_per_cycle': [float(x) for x in msd],
                            'moved_per_cycle': [float(x) for x in moved],
                            'msd_late': float(msd[-LAST:].mean()), 'moved_late': float(moved[-LAST:].mean())}
json.dump(result, open(os.path.join(HERE, 'summary.json'), 'w'), indent=1)
for name, r in result['runs'].items():
    print('%-14s gamma_0 %.1f  msd first %.3g  last %d cycles %.3g a^2  moved first %.2f  last %.2f'
          % (name, r['gamma_0'], r['msd_per_cycle'][0], LAST, r['msd_late'], r['moved_per_cycle'][0], r['moved_late']))

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt
fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
for name, r in result['runs'].items():
    k = np.arange(1, r['cycles'] + 1)
    left.semilogy(k, np.maximum(r['msd_per_cycle'], 1e-12), 'o-', ms=3, label='gamma_0 = %g' % r['gamma_0'])
    right.plot(k, r['moved_per_cycle'], 'o-', ms=3, label='gamma_0 = %g' % r['gamma_0'])
left.set_xlabel('cycle')
left.set_ylabel(r'stroboscopic $\langle|\Delta x|^2\rangle$ per cycle [$a^2$]')
right.set_xlabel('cycle')
right.set_ylabel('fraction of spheres moved > %g a' % THRESHOLD)
for ax in (left, right):
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
fig.suptitle('LD, Lees-Edwards cube 10a, 72 rough frictionless spheres, phi 0.3: oscillatory shear', fontsize=9)
fig.tight_layout()
fig.savefig(os.path.join(ROOT, 'doc', 'figures', 'irreversibility_ld.png'), dpi=100)
