"""The contact shear stress against strain of the phi 0.589, mu_d 0.5 runs at two stiffnesses
(doc/data/polydisperse/README.md "Where the frictional curves end"): core/stress_contact xy of
each run's series.h5, averaged over strain windows of +-0.005, into curves/jamming_p59.json.
    PYTHONPATH=python python3 doc/data/polydisperse/summarise_jamming_p59.py [OUT]   (OUT: out/polydisperse/curves)"""
import json
import os
import sys

import numpy as np
from fdsusp import series

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = sys.argv[1] if len(sys.argv) > 1 else 'out/polydisperse/curves'
RUNS = {'p59s': (8e-5, 0.002), 'p59t': (4e-5, 0.001)}
STRAINS = [0.02, 0.04, 0.06, 0.08, 0.10, 0.11, 0.12, 0.13, 0.14]

out = {'what': 'LD, Lees-Edwards cube 12a, phi 0.589 (deck 0.59), mu_d 0.5, eps_r 5e-3, seed 3: the contact part '
               'of the core shear stress, Sigma^c_xy (in eta gamma_dot_ref), averaged over strain windows of '
               '+-0.005 around each strain, at two contact stiffnesses; both runs stopped by the overlap guard '
               '(|delta\'| > h_r). Made by summarise_jamming_p59.py.', 'runs': {}}
for species in ('mix', 'eq'):
    for tag, (dt, eps_bar) in RUNS.items():
        name = '%s_mu05_%s' % (species, tag)
        s, _ = series.read(os.path.join(OUT, name), ['step', 'core/stress_contact'])
        strain = s['step'] * dt
        contact = s['core/stress_contact'][:, 3]
        points = []
        for x in STRAINS:
            m = (strain > x - 0.005) & (strain <= x + 0.005)
            if m.any():
                points.append([x, round(float(contact[m].mean()), 1)])
        out['runs'][name] = {'eps_bar': eps_bar, 'dt': dt, 'strain_reached': round(float(strain[-1]), 4),
                             'contact_stress_xy': points}
        print(name, 'eps_bar', eps_bar, 'to strain %.3f:' % strain[-1], ' '.join('%.2f:%g' % tuple(p) for p in points))
json.dump(out, open(os.path.join(HERE, 'curves', 'jamming_p59.json'), 'w'), indent=1)
