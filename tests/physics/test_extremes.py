"""Invariant: at every extreme scene of issue 8 (input/extremes) fdsusp either runs stably, the
largest rough-contact overlap below h_r/2 and every stress finite, or refuses before any work
with one message that names the limit. Short version for make check: each running scene for
100 steps (0.1 strain at dt = 1e-3, 0.05 at 5e-4; the full 5 strains are `make extremes`,
results in doc/VALIDATION.md §6), through scripts/extremes.py, which applies the criteria:
'stable' needs exit status 0, every step run, overlap < h_r/2 (the bound of the issue) and finite
stresslets and velocities; 'refused' needs status 2 with an input error and no time step taken.
The refusals are checked for the words that state their limit (phi055 and ld_phi055: frictional
spheres at phi 0.55 need contacts at least as stiff as eps_bar 0.005, whose overlaps the flowing
suspension keeps within the roughness, doc/VALIDATION.md §6; their frictionless twins run). The ld_* scenes are the same limits
in lubrication dynamics (&fluid model = 'none', issue 30)."""
import json
import os
import subprocess
import sys
import fdsusp_testlib as T

EXPECTED = {
    'phi050': ('stable', []), 'phi055_mu0': ('stable', []), 'mu1': ('stable', []),
    'phi055': ('refused', ['&contact', 'eps_bar', 'need stiffer contacts', 'overlap budget', 'eps_bar <=  5.00E-03']),
    'epsr1e-4': ('stable', []),
    'gamma1e-1': ('refused', ['&contact', 'eps_bar', 'flatten', 'eps_bar <=  7.']),
    'gamma1e-3': ('stable', []), 'dt5x': ('stable', []),
    'wall_touch': ('refused', ['&particles', 'position(:,1)', 'wall gap', 'h_r/2']),
    'pair_overlap': ('refused', ['&particles', 'position(:,1)', 'start at a gap of', 'h_r/2']),
    # lubrication dynamics (issue 30): the same limits without the fluid
    'ld_phi055_mu0': ('stable', []), 'ld_mu1': ('stable', []), 'ld_epsr1e-4': ('stable', []),
    'ld_phi055': ('refused', ['&contact', 'eps_bar', 'need stiffer contacts', 'overlap budget', 'eps_bar <=  5.00E-03']),
    'ld_dt_too_large': ('refused', ['&time', 'dt', 'the largest dt measured stable here is  2.00E-03']),
}
d = T.scratch('extremes')
report = os.path.join(d, 'extremes.json')
proc = subprocess.run([sys.executable, os.path.join(T.ROOT, 'scripts', 'extremes.py'), '--steps', '100',
                       '--jobs', '2', '--work', d, '--json', report], capture_output=True, text=True)
print(proc.stdout)
print(proc.stderr)
records = {r['scene']: r for r in json.load(open(report))}
T.check(sorted(records) == sorted(EXPECTED), 'every scene of input/extremes was run: %s' % sorted(records))
for name, (verdict, words) in EXPECTED.items():
    r = records.get(name)
    if r is None:
        continue
    T.check(r['verdict'] == verdict, '%s: %s (expected %s) %s' % (name, r['verdict'], verdict, r['message']))
    if verdict == 'stable':
        T.check(r['overlap_over_hr'] < 0.5, '%s: largest overlap %.4f h_r < 0.5' % (name, r['overlap_over_hr']))
    for w in words:
        T.check(w in r['message'], '%s: the message states %r' % (name, w))
T.finish()
