"""Order in shear at phi 0.55: Q6 (all bonds) and the mean local q6 against strain for the equal
spheres and the 1:1.4 mixture, from their series.h5 and summary.json.
    PYTHONPATH=python python3 doc/data/polydisperse/summarise_order.py OUT_EQUAL OUT_MIXTURE JSON PNG
(the runs: fdsusp doc/data/polydisperse/equal.nml, mixture.nml; see README.md there)."""
import json, os, sys
from fdsusp import series
import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt

out = {}
fig, ax = plt.subplots(1, 2, figsize=(10, 4))
outdirs = {'equal': sys.argv[1], 'mixture': sys.argv[2]}
counts = {}
for k, name in enumerate(('equal', 'mixture')):
    d = outdirs[name]
    s, a = series.read(d, ['time', 'structure/q6', 'structure/q6_local', 'particles/position'])
    counts[name] = s['particles/position'].shape[1]
    strain = s['time']
    q6, ql = s['structure/q6'], s['structure/q6_local']
    rows = {}
    for lo, hi in ((0, 1), (4, 6), (9, 11), (14, 16), (18, 20), (28, 30), (38, 40)):
        m = (strain >= lo) & (strain < hi)
        if m.any():
            rows[f'{lo}-{hi}'] = {'q6': float(q6[m].mean()), 'q6_local': float(ql[m].mean())}
    summ = json.load(open(os.path.join(d, 'summary.json')))
    out[name] = {'strain_last': float(strain[-1]), 'order_by_strain_window': rows,
                 'eta_r': summ['quantities']['eta_r'], 'phi_core': summ['quantities']['phi_core'],
                 'N1/tau': summ['quantities']['N1/tau'], 'N2/tau': summ['quantities']['N2/tau'],
                 'blocks_complete': summ['blocks_complete']}
    out[name]['spheres'] = counts[name]
    ax[0].plot(strain, q6, label=f'{name} ({counts[name]} spheres)')
    ax[1].plot(strain, ql, label=f'{name} ({counts[name]} spheres)')
for a_, lab in zip(ax, (r'$Q_6$ (all bonds)', r'mean local $q_6$')):
    a_.axhline(0.5745, color='k', ls=':', lw=0.8, label='fcc crystal')
    a_.set_xlabel(r'strain $\dot\gamma t$')
    a_.set_ylabel(lab)
    a_.legend(fontsize=8)
fig.suptitle('phi = 0.55, frictionless rough spheres, lubrication dynamics, Lees-Edwards box 13.2a')
fig.tight_layout()
fig.savefig(sys.argv[4], dpi=100)
json.dump(out, open(sys.argv[3], 'w'), indent=1)
print(json.dumps(out, indent=1))
