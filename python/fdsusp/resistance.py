"""Two-sphere and sphere-wall resistance: the exact functions and their measurement by fdsusp.

The exact functions are those of mod_pair_resistance, mod_wall_resistance and mod_pair_mobility,
printed by bin/fdsusp-resistance (doc/RESISTANCE.md): pair_scalars (the 22 equal-sphere scalars
of NAMES), wall_scalars and wall_excess, shear_functions (Batchelor & Green's A, B, ...).

The measurement is a run of fdsusp in resistance mode (velocities imposed, configuration held) or
'frozen' mode (force-free velocities at a fixed configuration), each a deck written by deck(),
whose steady force, torque and stresslet are extrapolated to pseudo-time infinity by aitken()
(steady()); m_fit() reads XM, YM, ZM off a stresslet; Runner runs a set of such decks on one
pinned copy of fdsusp. Shared by scripts/calibrate.py (the lubrication tables, doc/LUBRICATION.md),
frozen_pair.py, lubrication_table.py, tradeoff_pair.py, pair_dns.py (fdsusp.pair) and the physics
tests of the lubrication correction.
"""
import glob
import math
import os
import re
import shutil
import subprocess
import sys
import time

import h5py
import numpy as np

from . import deck as fdeck, series
from .run import ENV, MPIEXEC, program

NAMES = ["XA11", "YA11", "YB11", "XC11", "YC11", "XG11", "YG11", "YH11", "XM11", "YM11", "ZM11",
         "XA12", "YA12", "YB12", "XC12", "YC12", "XG12", "YG12", "YH12", "XM12", "YM12", "ZM12"]
WALL_NAMES = ["lambda_perp", "f_tt", "f_tr", "f_rr", "x_w"]
FREE_SPHERE_WALL = np.array([1.0, 1.0, 0.0, 1.0, 1.0])


def _table(kind, gaps, options=()):
    out = subprocess.run([program('fdsusp-resistance'), kind] + ['%.17g' % g for g in gaps] + list(options),
                         check=True, capture_output=True, text=True).stdout
    return np.array([[float(v) for v in line.split()] for line in out.splitlines() if not line.startswith('#')])


def pair_scalars(gap):
    """The 22 equal-sphere scalars at this gap, in the order of NAMES."""
    return _table('pair', [gap])[0, 1:]


def sized_pair(gap, size_ratio):
    """The 22 scalars of sphere 1 (radius 1) facing sphere 2 (radius size_ratio) at gap
    xi = 2r/(a1 + a2) - 2, Jeffrey & Onishi's scaling, in the order of NAMES (11 then 12)."""
    return _table('pair', [gap], ['--size-ratio', '%.17g' % size_ratio])[0, 1:]


def shear_functions(gaps):
    """Rows [A, B, C, K, L, M] of a force- and torque-free equal pair in a linear flow at these gaps
    (Batchelor & Green; mod_pair_mobility::pair_shear_functions): the relative velocity is
    dr/dt = Om x r + E.r - [A dd + B (I - dd)].E.r."""
    return _table('shear', list(gaps))[:, 1:]


def wall_scalars(gap):
    """[lambda_perp, f_tt, f_tr, f_rr, x_w] at this gap."""
    return _table('wall', [gap])[0, 1:]


def wall_excess(gap):
    """What one wall adds to the free-sphere values: wall_scalars(gap) - [1, 1, 0, 1, 1]."""
    return wall_scalars(gap) - FREE_SPHERE_WALL


def tabled_grids(root):
    """a/Delta of the full-model tables shipped in the checkout root (input/lubrication/resolved_a*.h5)."""
    found = []
    for path in glob.glob(os.path.join(root, 'input', 'lubrication', 'resolved_a*.h5')):
        m = re.search(r'resolved_a(\d+)\.h5$', path)
        if m:
            found.append(int(m.group(1)))
    return sorted(found)


# ---- measured by fdsusp ----
REYNOLDS = 0.01
BETA = 30.0          # rho/dt: the steady state does not depend on it (doc/METHOD.md §3.3); 30 converges fastest
STEPS = 100
EVERY = 20
# The Couette cell at shear rate 1 (u_x = y - Ly/2 about its mid-plane): strain rate and rotation
SHEAR_E = np.array([[0.0, 0.5, 0.0], [0.5, 0.0, 0.0], [0.0, 0.0, 0.0]])
SHEAR_OMEGA = np.array([0.0, 0.0, -0.5])


def with_flow(x, height):
    """A sphere at x moving and spinning with the undisturbed flow of a Couette cell this high."""
    return (x, np.array([x[1] - height / 2, 0.0, 0.0]), SHEAR_OMEGA)


def cells_per_radius(h):
    """a/Delta of a cell size h: an integer when it is one (the decks of the integer tables), else
    its value to 6 decimals (5.6 for the 1.4 species of a mixture at a/Delta 4), as table names
    write it."""
    n = round(1.0 / h, 6)
    return int(n) if n == int(n) else n


def deck(path, out, box, walls, shear, spheres, h, model='none', vtol=1e-6, ptol=1e-8, motion='resistance',
         radii=None, relax_radius=1.0):
    """spheres: list of (position, velocity, omega); motion: 'resistance' (the velocities imposed)
    or 'frozen' (the velocities force-free, scripts/frozen_pair.py); model: the lubrication model (calibration
    measures the resolved part alone, so 'none'); vtol, ptol: the solver tolerances; radii: each
    sphere's radius (spheres of several sizes: &particles radius and species(i)), else radius 1;
    relax_radius: the radius R the pseudo-time is set for, dt = Re R^2/BETA: a sphere of radius R
    then relaxes in STEPS steps as a unit sphere does at dt = Re/BETA (its diffusion time is
    Re R^2, and the relaxed constraint's gamma ~ (Re/dt) Delta^2 is the same in its cells; the
    steady state depends on neither). Written by fdsusp.deck (floats exactly)."""
    particles = {'number': len(spheres), 'motion': motion}
    if radii is not None and len(set(radii)) > 1:
        species = sorted(set(float(r) for r in radii))
        particles.update({'radius': species, 'species': [species.index(float(r)) + 1 for r in radii]})
    elif radii is not None:
        particles['radius'] = float(radii[0])
    for i, (x, u, w) in enumerate(spheres, 1):
        particles.update({'position(:,%d)' % i: [float(c) for c in x], 'velocity(:,%d)' % i: [float(c) for c in u],
                          'omega(:,%d)' % i: [float(c) for c in w]})
    fdeck.write(path, fdeck.text([
        ('domain', {'box': list(box), 'cells_per_radius': cells_per_radius(h),
                    'y_boundary': 'walls' if walls else 'periodic', 'shear_rate': shear}),
        ('fluid', {'reynolds': REYNOLDS, 'viscous_theta': 1.0, 'initial_flow': 'shear',
                   'velocity_tolerance': vtol, 'pressure_tolerance': ptol}),
        ('time', {'dt': REYNOLDS * relax_radius ** 2 / BETA, 'steps': STEPS}),
        ('output', {'directory': out, 'progress_every': STEPS, 'series_every': EVERY}),
        ('lubrication', {'model': model}),
        ('particles', particles)]))


def aitken(x):
    """Steady value of a geometrically converging sequence from its last three samples."""
    a, b, c = x[-3], x[-2], x[-1]
    d1, d2 = b - a, c - b
    den = d2 - d1
    with np.errstate(divide='ignore', invalid='ignore'):
        ratio = np.where(d1 != 0, d2 / d1, 0.0)
        est = np.where((np.abs(den) > 1e-14 * (np.abs(c) + 1)) & (ratio > 0) & (ratio < 0.95),
                       c - d2 * d2 / den, c)
    return est


def steady(out):
    """Force, torque and deviatoric stresslet of each sphere at pseudo-time infinity (aitken) from
    the run's series (fdsusp.series)."""
    cols = series.read(out, ['particles/force_hydro', 'particles/torque_hydro', 'particles/stresslet_hydro'])[0]
    F = aitken(cols['particles/force_hydro'])
    T = aitken(cols['particles/torque_hydro'])
    S = aitken(cols['particles/stresslet_hydro'])
    S = np.asarray(S)
    tr = np.trace(S, axis1=-2, axis2=-1)
    Sdev = S - tr[..., None, None] * np.eye(3) / 3.0
    return np.asarray(F), np.asarray(T), Sdev


def steady_with_lubrication(out):
    """Force and torque of each sphere, total and the lubrication correction's part, at pseudo-time
    infinity (aitken): F, T, F_lub, T_lub (zeros when the run has no correction)."""
    with h5py.File(os.path.join(out, 'series.h5'), 'r') as f:
        total = [aitken(f[k][:]) for k in ('particles/force_hydro', 'particles/torque_hydro')]
        lub = [aitken(f[k][:]) if k in f else np.zeros_like(total[0])
               for k in ('particles/force_lubrication', 'particles/torque_lubrication')]
    return total[0], total[1], lub[0], lub[1]


def strain_basis(d, E):
    ed = E @ d
    ded = d @ ed
    I = np.eye(3)
    dd = np.outer(d, d)
    d0 = 1.5 * (dd - I / 3) * ded
    d1 = np.outer(d, ed) + np.outer(ed, d) - 2 * dd * ded
    d2 = E + 0.5 * (I + dd) * ded - np.outer(d, ed) - np.outer(ed, d)
    return d0, d1, d2


def m_fit(S, d, E):
    """(XM, YM, ZM) such that S = (20/3) pi sum_k M_k D_k(d, E), least squares."""
    if strain_conditioning(d, E) < STRAIN_CONDITION:
        sys.exit('calibrate: the strain fit along d = %s is ill-conditioned' % d)
    basis = np.array([b.ravel() for b in strain_basis(d, E)]).T * (20.0 / 3.0 * math.pi)
    coef, *_ = np.linalg.lstsq(basis, S.ravel(), rcond=None)
    return coef


# Smallest singular value of the strain basis (9 x 3) below which the fit of (XM, YM, ZM) is refused:
# it is 0.41 at best (d along (1, 1, 1)), ~0 when d.E.d or E.d - (d.E.d) d vanishes (d in the
# x-z or y-z plane, or along an eigenvector of E), where the fit divides noise by ~0. The a/Delta = 4
# table of 2026-11-23 drew d = (0.002, -0.339, 0.941) (0.001) and its XM11 came out 0.50 at gap
# 0.35 between 1.46 (0.2) and 0.67 (0.6), scatter 0.47. 0.25 keeps ~35 % of random directions and
# amplifies the stresslet noise at most 1.6 times more than the best direction.
STRAIN_CONDITION = 0.25


def strain_conditioning(d, E):
    basis = np.array([b.ravel() for b in strain_basis(d, E)]).T
    return np.linalg.svd(basis, compute_uv=False).min()


class Runner:
    """Decks added by add() (deck() keywords), run by run() at most `jobs` at a time on one copy of
    fdsusp taken at construction, so that a rebuild of bin/ meanwhile cannot mix two builds in one
    set of measurements. A run whose output holds the file `done` is not repeated; a failed run
    stops the caller (calibrate: ...)."""

    def __init__(self, work, jobs):
        self.work, self.jobs, self.queue, self.count = work, jobs, [], 0
        self.binary = os.path.join(work, 'fdsusp')
        if os.path.exists(self.binary):
            os.remove(self.binary)
        shutil.copy2(program('fdsusp'), self.binary)

    def add(self, name, **kw):
        out = os.path.join(self.work, name)
        path = out + '.nml'
        deck(path, out, **kw)
        self.queue.append((name, path, out))
        return out

    def run(self):
        pending = list(self.queue)
        running = []
        t0 = time.time()
        done = 0
        while pending or running:
            while pending and len(running) < self.jobs:
                name, path, out = pending.pop(0)
                if os.path.exists(os.path.join(out, 'done')):
                    done += 1
                    continue
                log = open(out + '.log', 'w')
                p = subprocess.Popen(MPIEXEC + ['-n', '1', self.binary, path],
                                     stdout=log, stderr=subprocess.STDOUT, env=ENV)
                running.append((p, out, log))
            time.sleep(0.2)
            for item in list(running):
                p, out, log = item
                if p.poll() is not None:
                    log.close()
                    running.remove(item)
                    if p.returncode != 0:
                        sys.exit(f'calibrate: run {out} failed (status {p.returncode}), see {out}.log')
                    open(os.path.join(out, 'done'), 'w').close()
                    done += 1
                    if done % 10 == 0:
                        print(f'calibrate: {done}/{len(self.queue)} runs, {time.time() - t0:.0f} s', flush=True)
        self.queue = []
