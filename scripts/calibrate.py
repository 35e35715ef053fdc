#!/usr/bin/env python3
"""Measure the resolved two-sphere and sphere-wall resistance of fdsusp at one resolution and write
the lubrication table input/lubrication/resolved_a<N>.h5 (doc/METHOD.md §5.4; doc/LUBRICATION.md).

    scripts/calibrate.py CELLS_PER_RADIUS [--samples S] [--jobs J] [--work DIR]

Every measurement is a run of bin/fdsusp in resistance mode (velocities imposed, configuration
held, no lubrication correction): the steady resolved force, torque and stresslet of each sphere
are read from series.h5 and extrapolated to pseudo-time infinity (Aitken; fdsusp.resistance). For each gap
and each of S samples (a random sub-cell offset of the pair centre and a random direction d of
the line of centres):
  mode A (periodic 8a cube): the spheres translate at +-d (squeeze), sphere 1 spins about d
         -> XA11 - XA12, XG11 - XG12, XC11, XC12
  mode B (periodic): the spheres translate at +-e1 (sliding, e1 perpendicular to d), sphere 1
         spins about e1 -> YA11 - YA12, YB11 - YB12 (torque; the forces from the spin check
         reciprocity), YG11 - YG12, YC11, YC12, YH11, YH12
  mode C (Couette cell, shear rate 1): both spheres move with the undisturbed flow, along a line
         of centres where the strain fit is well conditioned (STRAIN_CONDITION, fdsusp.resistance)
         -> the sums XM11+XM12, YM11+YM12, ZM11+ZM12 (least squares over the stresslet)
and, per sample, the same three modes for one sphere alone (the one-body part, subtracted from
the rotation and strain functions so that only the pair interaction is corrected).
Why relative motions: a run with a net force in a periodic box has no steady state (the box
accelerates) and, with a balancing pressure gradient, feels the periodic images at O(a/L): at
8a they shifted XA12 by 14 % at gap 1 (measured). Relative (squeeze, sliding) motions exert no
net force, so their images are force dipoles, O((a/L)^3). The co-moving combinations (XA11 + XA12,
YA11 + YA12, YB11 + YB12, XG11 + XG12, YG11 + YG12) are regular at contact (their singular terms
cancel, doc/METHOD.md §5.2) and resolved by the grid; the
table gives them their exact values, i.e. the correction leaves them alone. For the relative
combinations the resolved one-body part is taken as exact (the hydrodynamic radius is 0.995-1.000a
at a/Delta = 5, doc/VALIDATION.md §2.1). The table holds, per gap, the
sample mean and standard deviation of the resolved pair part R~2B - R~1B for the 22 scalars (M
sums in the 11 slots, 0 in the 12 slots).
Sphere-wall (walls at rest, Ly = 10a): mode W1 (translate and spin along the normal n) and W2
(translate and spin along a tangent t), at each gap and, as the far reference, at the centre of
the cell; the resolved single-wall part is num(gap) - num(centre) corrected by the superposed
single-wall theory (bin/fdsusp-resistance) for the walls' far-field effects (doc/LUBRICATION.md).

Modes are separable because the cross terms land on other components (doc/METHOD.md §5.1 tensor
forms): translation along d gives no torque, rotation about d no force; translation along e1
torques about e2 = d x e1 and rotation about e1 forces along e2.
"""
import argparse, math, os, sys
import numpy as np
import h5py
import _fdsusp_path  # noqa: F401,E402  (this checkout's python/ on sys.path)
from fdsusp.resistance import (NAMES, WALL_NAMES, SHEAR_E, STRAIN_CONDITION, Runner, m_fit,  # noqa: E402
                               pair_scalars, steady, strain_conditioning, wall_excess, with_flow)
from fdsusp import pair_blocks as pb  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GAPS = [0.001, 0.01, 0.05, 0.1, 0.2, 0.35, 0.6, 1.0]
WALL_GAPS = [0.001, 0.01, 0.05, 0.1, 0.2, 0.35, 0.6, 1.0]
IDX = {n: i for i, n in enumerate(NAMES)}
# samples per gap of the shipped tables: a/Delta = 5 takes 4 because its first two samples both sat
# at the top of the +-3 % direction spread of the resolved XG11 - XG12, which a free pair's radial
# mobility amplifies (doc/VALIDATION.md §4.1, §4.4); the others keep 2
SAMPLES = {5: 4}
PI = math.pi


def strain_direction(d, E, seed):
    """Line of centres for mode C: d itself when the strain fit is well conditioned there, else a
    random direction that is (drawn from its own generator, so the other modes' samples and the
    tables calibrated before this rule, whose directions passed it, are unchanged)."""
    rng = np.random.default_rng(seed)
    while strain_conditioning(d, E) < STRAIN_CONDITION:
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
    return d


def frame(rng):
    d = rng.normal(size=3)
    d /= np.linalg.norm(d)
    e1 = np.cross(d, rng.normal(size=3))
    e1 /= np.linalg.norm(e1)
    return d, e1, np.cross(d, e1)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('cells_per_radius', type=float,
                    help='a/Delta; not an integer for the larger species of a mixture (5.6 = 1.4 x 4)')
    ap.add_argument('--samples', type=int, default=None, help='samples per gap (default: SAMPLES, else 2)')
    ap.add_argument('--jobs', type=int, default=2)
    ap.add_argument('--work', default=None)
    ap.add_argument('--output', default=None)
    ap.add_argument('--size-ratio', type=float, default=None,
                    help='an unequal pair: sphere 2 of radius SIZE_RATIO times sphere 1 (of CELLS_PER_RADIUS)')
    args = ap.parse_args()
    # an integer resolution stays one: the names, seeds and decks of the integer tables
    n = args.cells_per_radius
    args.cells_per_radius = int(n) if n == int(n) else n
    if args.size_ratio is not None:
        calibrate_unequal(args)
        return
    if args.samples is None:
        args.samples = SAMPLES.get(args.cells_per_radius, 2)
    if args.samples < 2:
        ap.error('--samples must be at least 2 (the table keeps the scatter)')
    n = args.cells_per_radius
    h = 1.0 / n
    work = args.work or os.path.join(ROOT, 'out', f'calibrate_a{ratio_tag(n)}')
    os.makedirs(work, exist_ok=True)
    # the seed of the integer tables; a non-integer resolution seeds with 1000 n
    rng = np.random.default_rng(20261123 + (n if isinstance(n, int) else int(round(1000 * n))))
    # the periodic cube (8a) and the Couette cell (10a) in whole cells (8 and 10 exactly when n is an integer)
    L = round(8.0 * n) / n
    LW = round(10.0 * n) / n
    E = SHEAR_E
    zero = np.zeros(3)
    runner = Runner(work, args.jobs)
    samples = []
    for s in range(args.samples):
        off = rng.uniform(0, h, size=3)
        d, e1, e2 = frame(rng)
        rng.uniform(0, 2 * PI)   # a discarded draw: it keeps the random stream, hence the tables' samples
        ang = rng.uniform(0, 2 * PI)
        t = np.array([math.cos(ang), 0.0, math.sin(ang)])
        dc = strain_direction(d, E, seed=int(round(20261125 + 100 * n)) + s)
        samples.append((off, d, e1, e2, t, dc))
        c = np.array([L / 2, L / 2, L / 2]) + off
        cc = np.array([L / 2, LW / 2, L / 2]) + off
        runner.add(f's{s}_one_A', box=(L, L, L), walls=False, shear=0.0, spheres=[(c, d, d)], h=h)
        runner.add(f's{s}_one_B', box=(L, L, L), walls=False, shear=0.0, spheres=[(c, e1, e1)], h=h)
        runner.add(f's{s}_one_C', box=(L, LW, L), walls=True, shear=1.0, spheres=[with_flow(cc, LW)], h=h)
        for g in GAPS:
            x1, x2 = c - (1 + g / 2) * d, c + (1 + g / 2) * d
            runner.add(f's{s}_g{g}_A', box=(L, L, L), walls=False, shear=0.0,
                       spheres=[(x1, d, d), (x2, -d, zero)], h=h)
            runner.add(f's{s}_g{g}_B', box=(L, L, L), walls=False, shear=0.0,
                       spheres=[(x1, e1, e1), (x2, -e1, zero)], h=h)
            y1, y2 = cc - (1 + g / 2) * dc, cc + (1 + g / 2) * dc
            runner.add(f's{s}_g{g}_C', box=(L, LW, L), walls=True, shear=1.0,
                       spheres=[with_flow(y1, LW), with_flow(y2, LW)], h=h)
        n_wall = np.array([0.0, 1.0, 0.0])
        for g in WALL_GAPS + ['centre']:
            y = LW / 2 if g == 'centre' else 1.0 + g
            x = np.array([L / 2 + off[0], y, L / 2 + off[2]])
            runner.add(f's{s}_w{g}_W1', box=(L, LW, L), walls=True, shear=0.0, spheres=[(x, n_wall, n_wall)], h=h)
            runner.add(f's{s}_w{g}_W2', box=(L, LW, L), walls=True, shear=0.0, spheres=[(x, t, t)], h=h)
    runner.run()

    # ---- reduce ----
    pair = np.zeros((args.samples, len(GAPS), 22))
    recip = []
    wall = np.zeros((args.samples, len(WALL_GAPS), 5))
    one_body = []
    for s, (off, d, e1, e2, t, dc) in enumerate(samples):
        o = {}
        F, T, S = steady(os.path.join(work, f's{s}_one_A'))
        # rotation and strain one-body parts are subtracted; the translational ones are kept as a
        # record only (a net force in a periodic box: see the module doc)
        o['XA'] = -F[0] @ d / (6 * PI); o['XC'] = -T[0] @ d / (8 * PI)
        F, T, S = steady(os.path.join(work, f's{s}_one_B'))
        o['YA'] = -F[0] @ e1 / (6 * PI); o['YC'] = -T[0] @ e1 / (8 * PI); o['YH'] = (e2 @ S[0] @ d) / (8 * PI)
        F, T, S = steady(os.path.join(work, f's{s}_one_C'))
        o['XM'], o['YM'], o['ZM'] = m_fit(S[0], dc, E)
        one_body.append(o)
        for k, g in enumerate(GAPS):
            ex = pair_scalars(g)
            E_ = {n_: ex[i_] for i_, n_ in enumerate(NAMES)}
            f = np.zeros(22)

            def split(name, diff):
                # relative motion (w_2 = -w_1) measures the pair part of f11 - f12, where the
                # singular terms are; f11 + f12 keeps its exact value (see the module doc)
                e11, e12 = E_[name + '11'] - (1.0 if name in ('XA', 'YA') else 0.0), E_[name + '12']
                f[IDX[name + '11']], f[IDX[name + '12']] = 0.5 * (e11 + e12 + diff), 0.5 * (e11 + e12 - diff)
            F, T, S = steady(os.path.join(work, f's{s}_g{g}_A'))
            # squeeze U_1 = d = -U_2: F_1.d = -6 pi (XA11 - XA12); one body taken as exact (1)
            split('XA', -F[0] @ d / (6 * PI) - 1.0)
            f[IDX['XC11']] = -T[0] @ d / (8 * PI) - o['XC']
            f[IDX['XC12']] = -T[1] @ d / (8 * PI)
            # S_1 = 4 pi [XG11 (d.w_1) + XG12 (d.w_2)](dd - I/3), w_1 = -d = -w_2
            split('XG', -1.5 * (d @ S[0] @ d) / (4 * PI))
            F, T, S = steady(os.path.join(work, f's{s}_g{g}_B'))
            split('YA', -F[0] @ e1 / (6 * PI) - 1.0)
            f[IDX['YC11']] = -T[0] @ e1 / (8 * PI) - o['YC']
            f[IDX['YC12']] = -T[1] @ e1 / (8 * PI)
            # T_1 = 4 pi [YB11 (w_1 x d) + YB12 (w_2 x d)] = 4 pi (YB11 - YB12) e2
            split('YB', T[0] @ e2 / (4 * PI))
            recip.append((g, T[0] @ e2 / (4 * PI), -F[0] @ e2 / (4 * PI), -F[1] @ e2 / (4 * PI)))
            split('YG', -(e1 @ S[0] @ d) / (4 * PI))
            f[IDX['YH11']] = (e2 @ S[0] @ d) / (8 * PI) - o['YH']
            f[IDX['YH12']] = (e2 @ S[1] @ d) / (8 * PI)
            F, T, S = steady(os.path.join(work, f's{s}_g{g}_C'))
            m = 0.5 * (m_fit(S[0], dc, E) + m_fit(S[1], dc, E))
            f[IDX['XM11']] = m[0] - o['XM']
            f[IDX['YM11']] = m[1] - o['YM']
            f[IDX['ZM11']] = m[2] - o['ZM']
            pair[s, k] = f
        n_wall = np.array([0.0, 1.0, 0.0])
        b = np.cross(n_wall, t)

        def wall_values(tag):
            F, T, S = steady(os.path.join(work, f's{s}_w{tag}_W1'))
            lam = -F[0] @ n_wall / (6 * PI)
            xw = -T[0] @ n_wall / (8 * PI)
            F, T, S = steady(os.path.join(work, f's{s}_w{tag}_W2'))
            ftt = -F[0] @ t / (6 * PI)
            ftr = T[0] @ b / (6 * PI)
            frr = -T[0] @ t / (8 * PI)
            return np.array([lam, ftt, ftr, frr, xw])
        centre = wall_values('centre')
        for k, g in enumerate(WALL_GAPS):
            # single-wall resolved part: remove the far wall at distance LW - 2 - g and the two
            # walls seen from the centre by superposing single-wall theory (doc/LUBRICATION.md)
            far = wall_excess(LW - 2.0 - g)
            mid = 2.0 * wall_excess(LW / 2 - 1.0)
            wall[s, k] = wall_values(g) - centre - far + mid
    out = args.output or os.path.join(ROOT, 'input', 'lubrication', f'resolved_a{ratio_tag(n)}.h5')
    os.makedirs(os.path.dirname(out), exist_ok=True)
    with h5py.File(out, 'w') as f:
        f.attrs['cells_per_radius'] = n
        f.attrs['radius_offset'] = 0.38
        f.attrs['slip_kappa'] = 0.5
        f.attrs['command'] = f'scripts/calibrate.py {ratio_tag(n)} --samples {args.samples}'
        f.attrs['description'] = ('resolved pair part R~2B - R~1B of the 22 equal-sphere scalars '
                                  '(Kim & Karrila normalisation; M sums in the 11 slots) and of the '
                                  'sphere-wall functions, measured by fdsusp in resistance mode')
        # rows: gap, then the scalars (Fortran reads them as (1 + n, ngaps))
        g = np.array(GAPS)[:, None]
        f.create_dataset('pair/resolved', data=np.hstack([g, pair.mean(axis=0)]))
        f.create_dataset('pair/scatter', data=np.hstack([g, pair.std(axis=0, ddof=1)]))
        f['pair'].attrs['columns'] = 'gap,' + ','.join(NAMES)
        g = np.array(WALL_GAPS)[:, None]
        f.create_dataset('wall/resolved', data=np.hstack([g, wall.mean(axis=0)]))
        f.create_dataset('wall/scatter', data=np.hstack([g, wall.std(axis=0, ddof=1)]))
        f['wall'].attrs['columns'] = 'gap,' + ','.join(WALL_NAMES)
        f.create_dataset('one_body', data=np.array([[o[k] for k in ('XA', 'YA', 'XC', 'YC', 'XM', 'YM', 'ZM')]
                                                    for o in one_body]))
        f['one_body'].attrs['names'] = 'XA,YA,XC,YC,XM,YM,ZM'
        f.create_dataset('reciprocity_yb', data=np.array(recip))
        f['reciprocity_yb'].attrs['columns'] = ('gap,YB11 - YB12 from the torque on sphere 1,'
                                                'YB11 from the force on sphere 1,YB12 from the force on sphere 2')
    print(f'calibrate: wrote {out}')


# ---- unequal pairs (doc/LUBRICATION.md "Tables for mixtures") ----

def pair_motions(gap, lam, d, e1):
    """The imposed motions (U (2, 3), Omega (2, 3)) of the pair runs in the periodic cube:
    A squeeze along d with sphere 1 spinning about d, A2 sphere 2 spinning about d, B sliding along
    e1 with sphere 1 spinning about e1, B2 sphere 2 spinning about e1. Unequal spheres in relative
    motion, or a sphere spinning beside another, exert a net force, and a periodic box under a net
    force has no steady state (its fluid accelerates: 2-3 % of the squeeze force at lambda = 2 by
    the end of the pseudo-time). So each run adds to both spheres the co-moving translation that
    makes the exact net force vanish (a regular motion, which the fit models like the rest); what
    is left is the grid's own imbalance."""
    s = pb.exact_scalars(gap, lam)
    zero = np.zeros(3)
    primary = {'A': ([d, -d], [d, zero]), 'A2': ([zero, zero], [zero, d]),
               'B': ([e1, -e1], [e1, zero]), 'B2': ([zero, zero], [zero, e1])}
    motions = {}
    for mode, (u, o) in primary.items():
        o = np.array(o, dtype=float)
        motions[mode] = (pb.balanced(s, 1.0, lam, d, u, o), o)
    return motions


def ratio_tag(value):
    """The shortest decimal of a resolution or size ratio, as table names write it (4, 5.6, 1.4)."""
    return ('%.6f' % value).rstrip('0').rstrip('.')


# the unknowns of the fit: every block scalar but the cross M slots (folded into the self slots)
FREE = [(k, al, be) for k in range(11) for al in range(2) for be in range(2)
        if not (pb.NAMES11[k] in ('XM', 'YM', 'ZM') and al != be)]
# weight of the co-moving rows: they pin the regular combinations to their exact values
COMOVING_WEIGHT = 100.0


def calibrate_unequal(args):
    """The resolved pair part of spheres of radii 1 (at CELLS_PER_RADIUS) and lam: every mode of
    the equal calibration, each sphere spun in turn, fitted with fdsusp.pair_blocks (see
    fit_pair), the regular co-moving translations held at their exact values."""
    n, lam = args.cells_per_radius, args.size_ratio
    if lam < 1.0:
        sys.exit('calibrate: --size-ratio is the larger sphere over the smaller, >= 1 (1: the equal pair '
                 'by this method, a check of it against the equal table)')
    samples_n = args.samples or 2
    h = 1.0 / n
    a1, a2 = 1.0, lam
    tag = f'a{ratio_tag(n)}_ratio{ratio_tag(lam)}'
    work = args.work or os.path.join(ROOT, 'out', f'calibrate_{tag}')
    os.makedirs(work, exist_ok=True)
    rng = np.random.default_rng(int(round(20261127 + n + 100 * lam)))
    # the periodic cube and the Couette cell scaled with the pair (8a and 10a for equal spheres),
    # whole cells
    L = round(4.0 * (a1 + a2) * n) / n
    LW = round(5.0 * (a1 + a2) * n) / n
    E = SHEAR_E
    zero = np.zeros(3)
    radii = [a1, a2]
    # the pseudo-time relaxes over the larger sphere's diffusion time Re a2^2: its steps are set
    # for a2 (fdsusp.resistance.deck relax_radius), so that the large sphere relaxes in the 100
    # steps as the equal table at its resolution N a2 does, step for step in its cells
    runner = Runner(work, args.jobs)
    samples = []
    for s in range(samples_n):
        off = rng.uniform(0, h, size=3)
        d, e1, e2 = frame(rng)
        dc = strain_direction(d, E, seed=int(round(20261127 + 100 * n)) + s)
        samples.append((off, d, e1, e2, dc))
        c = np.array([L / 2, L / 2, L / 2]) + off
        cc = np.array([L / 2, LW / 2, L / 2]) + off
        # one body: each sphere alone at the pair's centre, spinning as in the pair runs, and
        # with the flow (its rotation and strain parts are subtracted)
        for k, a in enumerate(radii, 1):
            one = dict(h=h, radii=[a], relax_radius=a2)
            runner.add(f's{s}_one{k}_A', box=(L, L, L), walls=False, shear=0.0, spheres=[(c, zero, d)], **one)
            runner.add(f's{s}_one{k}_B', box=(L, L, L), walls=False, shear=0.0, spheres=[(c, zero, e1)], **one)
            runner.add(f's{s}_one{k}_C', box=(L, LW, L), walls=True, shear=1.0, spheres=[with_flow(cc, LW)], **one)
        for g in GAPS:
            r = (a1 + a2) * (1 + g / 2)
            x1, x2 = c - 0.5 * r * d, c + 0.5 * r * d
            pair = dict(h=h, radii=radii, relax_radius=a2)
            for mode, (u, o) in pair_motions(g, lam, d, e1).items():
                runner.add(f's{s}_g{g}_{mode}', box=(L, L, L), walls=False, shear=0.0,
                           spheres=[(x1, u[0], o[0]), (x2, u[1], o[1])], **pair)
            y1, y2 = cc - 0.5 * r * dc, cc + 0.5 * r * dc
            runner.add(f's{s}_g{g}_C', box=(L, LW, L), walls=True, shear=1.0,
                       spheres=[with_flow(y1, LW), with_flow(y2, LW)], **pair)
    runner.run()

    # ---- reduce: per sample and gap, the fit of the block scalars ----
    table = np.zeros((samples_n, len(GAPS), 44))
    residuals = np.zeros((samples_n, len(GAPS)))
    quiet = np.zeros((3, 3))
    for s, (off, d, e1, e2, dc) in enumerate(samples):
        one = {}
        for k in (1, 2):
            for mode in 'ABC':
                one[k, mode] = steady(os.path.join(work, f's{s}_one{k}_{mode}'))
        for gi, g in enumerate(GAPS):
            exact = pb.exact_pair_part(g, lam)
            measured = []

            def pair_part(mode, velocities, spins, with_flow_=False):
                """The measured pair responses of a run, one-body parts removed: the exact drag
                of each translating sphere, the measured one-body torque and stresslet of each
                spinning sphere (and of each sphere in the flow)."""
                F, T, S = steady(os.path.join(work, f's{s}_g{g}_{mode}'))
                F, T, S = F.copy(), T.copy(), S.copy()
                for al, a in enumerate(radii):
                    F[al] += 6 * PI * a * np.asarray(velocities[al])
                    if spins[al] is not None:
                        F1, T1, S1 = one[al + 1, spins[al]]
                        T[al] -= T1[0]
                        S[al] -= S1[0]
                        if with_flow_:
                            F[al] -= F1[0]
                w = np.zeros((2, 6))
                if not with_flow_:
                    w[:, :3] = -np.array(velocities)
                return w, F, T, S

            for mode, (u, o) in pair_motions(g, lam, d, e1).items():
                # the one-body run of the spinning sphere: about d (A, A2) or about e1 (B, B2)
                spinning = [mode[0] if np.any(o[al] != 0) else None for al in range(2)]
                w, F, T, S = pair_part(mode, u, spinning)
                w[:, 3:] = -o
                measured.append((w, quiet, F, T, S))
            w, F, T, S = pair_part('C', [zero, zero], ['C', 'C'], with_flow_=True)
            # the strain run's line of centres is dc: refit it in the frame of d below
            comoving = []
            for u in (d, e1, e2):
                wc = np.zeros((2, 6))
                wc[:, :3] = -u
                comoving.append((wc, quiet) + pb.responses(exact, a1, a2, d, wc, quiet))
            # modes A, B and the co-moving rows share d; mode C has its own line of centres dc,
            # so its rows join the fit through the response model in that frame
            s_fit, res = fit_pair(measured, comoving, (w, E, F, T, S), a1, a2, d, dc)
            residuals[s, gi] = res
            f, f2 = pb.to_arrays(s_fit)
            table[s, gi] = np.concatenate([f, f2])
    out = args.output or os.path.join(ROOT, 'input', 'lubrication', f'resolved_{tag}.h5')
    os.makedirs(os.path.dirname(out), exist_ok=True)
    names = [n + '11' for n in pb.NAMES11] + [n + '12' for n in pb.NAMES11]
    names += [n + '22' for n in pb.NAMES11] + [n + '21' for n in pb.NAMES11]
    with h5py.File(out, 'w') as fh:
        fh.attrs['cells_per_radius'] = float(n)
        fh.attrs['size_ratio'] = float(lam)
        fh.attrs['radius_offset'] = 0.38
        fh.attrs['slip_kappa'] = 0.5
        fh.attrs['command'] = f'scripts/calibrate.py {ratio_tag(n)} --size-ratio {ratio_tag(lam)} --samples {samples_n}'
        fh.attrs['description'] = ('resolved pair part R~2B - R~1B of two spheres of radii 1 and size_ratio '
                                   '(Jeffrey & Onishi scaling; sphere 1: 11 and 12 scalars, sphere 2: 22 and 21 '
                                   'with exchange signs; M folded into the self slots), measured by fdsusp in '
                                   'resistance mode and fitted with fdsusp.pair_blocks')
        gcol = np.array(GAPS)[:, None]
        fh.create_dataset('pair/resolved', data=np.hstack([gcol, table.mean(axis=0)]))
        fh.create_dataset('pair/scatter', data=np.hstack([gcol, table.std(axis=0, ddof=1)]))
        fh['pair'].attrs['columns'] = 'gap,' + ','.join(names)
        fh.create_dataset('fit_residual', data=np.hstack([gcol, residuals.T]))
        fh['fit_residual'].attrs['columns'] = 'gap, then per sample the relative residual of the fit'
    print(f'calibrate: wrote {out}; largest relative fit residual {residuals.max():.3g}')


def fit_pair(measured, comoving, strain_run, a1, a2, d, dc):
    """The resolved pair scalars (M folded) that best reproduce the measured pair responses, by
    linear least squares (the responses are linear in the scalars: each column is the response to
    one scalar). measured: (w (2, 6), e (3, 3), F (2, 3), T (2, 3), S (2, 3, 3)) of the runs along
    d, one-body parts removed; strain_run: the same of the run in the flow, whose line of centres is
    dc (the scalars do not depend on the frame); comoving: (w, e, F, T, S) that the exact pair part
    gives for co-moving translations, weighted COMOVING_WEIGHT so that the regular combinations keep
    their exact values. Rows are scaled by each sphere's one-body drag, rotational and strain
    resistance. Returns the scalars and the relative residual of the measured rows."""
    scale = [(6 * PI * a, 8 * PI * a ** 3, 20.0 / 3.0 * PI * a ** 3) for a in (a1, a2)]

    def rows(F, T, S):
        return np.concatenate([np.concatenate([F[al] / scale[al][0], T[al] / scale[al][1],
                                               S[al].ravel() / scale[al][2]]) for al in range(2)])

    design, target = [], []
    n_meas = 0
    groups = [(measured, d, 1.0), ([strain_run], dc, 1.0), (comoving, d, COMOVING_WEIGHT)]
    for items, frame_d, weight in groups:
        for w, e, F, T, S in items:
            cols = []
            for k, al, be in FREE:
                unit = np.zeros((11, 2, 2))
                unit[k, al, be] = 1.0
                cols.append(rows(*pb.responses(unit, a1, a2, frame_d, w, e)))
            design.append(weight * np.array(cols).T)
            target.append(weight * rows(F, T, S))
            if weight == 1.0:
                n_meas += len(target[-1])
    A, b = np.vstack(design), np.concatenate(target)
    x, *_ = np.linalg.lstsq(A, b, rcond=None)
    s = np.zeros((11, 2, 2))
    for v, (k, al, be) in zip(x, FREE):
        s[k, al, be] = v
    residual = np.linalg.norm((A @ x - b)[:n_meas]) / max(np.linalg.norm(b[:n_meas]), 1e-300)
    return s, residual


if __name__ == '__main__':
    main()
