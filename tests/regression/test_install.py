"""Invariant: an installed copy stands alone. `make install PREFIX=...` puts the programs, the
lubrication tables, the decks and the docs under PREFIX, and the installed fdsusp finds its table
beside itself (PREFIX/share/fdsusp/lubrication), not in the build tree; FDSUSP_TABLE_DIR, when set,
is where it looks instead. Checked by the path the run log names and by a run that completes:
  1. the installed tree holds bin/fdsusp, bin/fdsusp-pack, bin/pairtraj, the four shipped tables,
     input/demo.nml and share/doc/fdsusp/README.md;
  2. a two-sphere deck with full lubrication (a/Delta = 4), run by the installed program from a
     scratch directory, logs 'lubrication table: PREFIX/bin/../share/fdsusp/lubrication/...' and
     finishes;
  3. with FDSUSP_TABLE_DIR pointing at an empty directory the same run is refused, naming that
     directory (the variable wins), before any step;
  4. the Python package: PREFIX/share/fdsusp/python/fdsusp holds every module of python/fdsusp;
     imported from there (PYTHONPATH, from a scratch directory, FDSUSP_BIN unset) it is that copy,
     it finds the installed programs (PREFIX/bin/fdsusp) and its series reader reads the run of 2;
     the installed PREFIX/share/fdsusp/scripts/series.py (no PYTHONPATH) prints that run's records.
"""
import glob
import os
import subprocess
import sys

import fdsusp_testlib as T  # noqa: E402

prefix = T.scratch('install_prefix')
p = subprocess.run(['make', '-s', '-C', T.ROOT, 'install', 'PREFIX=' + prefix], capture_output=True, text=True,
                   env=T.ENV)
T.check(p.returncode == 0, 'make install PREFIX=%s (status %d) %s' % (prefix, p.returncode, p.stderr[-300:]))
wanted = ['bin/fdsusp', 'bin/fdsusp-pack', 'bin/pairtraj'] + \
         ['share/fdsusp/lubrication/resolved_a%d.h5' % n for n in (4, 5, 6, 8)] + \
         ['share/fdsusp/input/demo.nml', 'share/doc/fdsusp/README.md']
missing = [w for w in wanted if not os.path.exists(os.path.join(prefix, w))]
T.check(not missing, 'the installed tree holds %d files (missing: %s)' % (len(wanted), missing))

DECK = """&domain box = 8, 8, 8, cells_per_radius = 4 /
&fluid reynolds = 0.01 /
&time dt = 1e-3, steps = 2 /
&output directory = 'out' /
&lubrication model = 'full' /
&particles number = 2, position(:,1) = 2.9, 4, 4, position(:,2) = 5.1, 4, 4 /
"""
d = T.scratch('install_run')
deck = T.write_deck(d, 'd.nml', DECK)
fdsusp = os.path.join(prefix, 'bin', 'fdsusp')
env = dict(T.ENV)
env.pop('FDSUSP_TABLE_DIR', None)
p = subprocess.run([fdsusp, deck], cwd=d, env=env, capture_output=True, text=True, timeout=300)
table = [l for l in p.stdout.splitlines() if l.startswith('lubrication table:')]
expected = os.path.join(prefix, 'bin', '..', 'share', 'fdsusp', 'lubrication', 'resolved_a4.h5')
T.check(p.returncode == 0 and 'finished at step 2' in p.stdout,
        'the installed fdsusp runs the deck (status %d)' % p.returncode)
T.check(len(table) == 1 and table[0].split(':', 1)[1].strip() == expected,
        'it reads the installed table: %s' % (table[0] if table else 'no table line'))

empty = T.scratch('install_no_tables')
env['FDSUSP_TABLE_DIR'] = empty
d2 = T.scratch('install_run_env')
deck = T.write_deck(d2, 'd.nml', DECK)
p = subprocess.run([fdsusp, deck], cwd=d2, env=env, capture_output=True, text=True, timeout=300)
messages = [l for l in p.stderr.splitlines() if l.startswith('fdsusp:')]
T.check(p.returncode != 0 and len(messages) == 1 and empty in messages[0] and 'step ' not in p.stdout,
        'FDSUSP_TABLE_DIR wins: an empty one is refused by name before any step (status %d, %s)'
        % (p.returncode, messages[:1]))

# 4. the Python package, installed beside the programs
package = os.path.join(prefix, 'share', 'fdsusp', 'python')
modules = sorted(os.path.basename(m) for m in glob.glob(os.path.join(T.ROOT, 'python', 'fdsusp', '*.py')))
missing = [m for m in modules if not os.path.exists(os.path.join(package, 'fdsusp', m))]
T.check(len(modules) >= 7 and not missing, 'the installed package holds the %d modules of python/fdsusp (missing: %s)'
        % (len(modules), missing))
env = dict(T.ENV, PYTHONPATH=package)
env.pop('FDSUSP_BIN', None)
code = ('import fdsusp, fdsusp.run, fdsusp.series, fdsusp.rheology, fdsusp.deck; print(fdsusp.__file__); '
        'print(fdsusp.run.program("fdsusp")); print(len(fdsusp.series.read(%r)[0]["step"]))' % os.path.join(d, 'out'))
p = subprocess.run([sys.executable, '-c', code], cwd=empty, env=env, capture_output=True, text=True, timeout=120)
lines = p.stdout.split()
T.check(p.returncode == 0 and len(lines) == 3 and lines[0].startswith(os.path.join(package, 'fdsusp') + os.sep),
        'import fdsusp from PREFIX/share/fdsusp/python is the installed copy (%s %s)' % (lines[:1], p.stderr[-300:]))
T.check(p.returncode == 0 and len(lines) == 3 and lines[1] == os.path.join(prefix, 'bin', 'fdsusp'),
        'the installed package finds the installed fdsusp: %s' % lines[1:2])
T.check(p.returncode == 0 and len(lines) == 3 and int(lines[2]) > 0,
        'the installed fdsusp.series reads the installed program\'s run (%s records)' % lines[2:3])
script = os.path.join(prefix, 'share', 'fdsusp', 'scripts', 'series.py')
env.pop('PYTHONPATH')       # the installed scripts find the installed package by themselves
p = subprocess.run([sys.executable, script, os.path.join(d, 'out')], cwd=empty, env=env, capture_output=True,
                   text=True, timeout=120)
T.check(p.returncode == 0 and 'records, steps' in p.stdout,
        'the installed scripts/series.py runs on it, without PYTHONPATH (%s)' % (p.stdout.splitlines()[:1] or p.stderr[-200:]))
T.finish()
