#!/usr/bin/env python3
"""Rheology of fdsusp runs from their series.h5 (doc/RHEOLOGY.md).

    scripts/rheology.py OUTDIR [OUTDIR ...] [--plots DIR] [--compare] [--window D A B] [--json FILE]
    scripts/rheology.py --records SUMMARY.json [...] --plots DIR


For each output directory, recomputes the summary of the core region from series.h5 alone, by
the rules of src/kernels/rheology.F90 (records on the series_every grid after discard_step, `blocks`
blocks of block_steps steps, quantities evaluated on the block means; value from the mean of the
block means, error = standard deviation over the complete blocks (ddof 1) / sqrt(blocks)), and
prints it. --compare: also compare with the run's own summary.json and exit 1 if any number
differs by more than 1e-10 (relative). --window DISCARD AVERAGE BLOCKS: the statistics over
another window than the run's &rheology (strains discarded and averaged, blocks), e.g. a later
window of a run extended from its checkpoint, or the paper's 50 transient strains; steps are
rounded as src/runtime/params.F90 rounds them. --json FILE (one OUTDIR): write the recomputed
summary there, with the keys of fdsusp's summary.json. --plots DIR: PNG figures: per run the core stress time
series, phi(y) and u_x(y), g(theta) and g_c(theta) (paper figs. 6 and 15); over all runs given,
eta_r, N1/tau and N2/tau against phi_core, one series per friction coefficient (paper figs. 9,
11).

--records: the figures of the paper's comparisons from recorded summaries (summary.json with the
"run" object that scripts/friction_study.py adds, e.g. doc/data/friction_phi04/*/summary.json),
no series needed: paper_fig9.png (eta_r, eta_h against phi_core with the Zarraga et al. 2000 fit
and the paper's eta_inf), paper_fig11.png (N1/tau, N2/tau with the Dai et al. 2013 fits),
paper_fig16.png (eta_r, N1/tau, N2/tau against mu_d for each set-up, dt aside, with three or
more frictions: at each mu_d the run of the smallest dt), paper_fig20_22.png (normal viscosity with Morris & Boulay 1999; phi and mu against
I_v with Boyer, Guazzelli & Pouliquen 2011); and from the records of extended runs
(scripts/friction_study.py --extend, with "by_strain") friction_by_strain.png (eta_r, phi_core and
N2/tau over successive strain windows).
"""
import argparse
import json
import math
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import series  # noqa: E402

# order and definitions as mod_rheology::rheo_quantities
NAMES = ['eta_r', 'eta_h', 'eta_c', 'N1/tau', 'N2/tau', 'Pi/tau',
         'Sigma_xx/tau', 'Sigma_yy/tau', 'Sigma_zz/tau', 'Sigma_xx_c/tau', 'Sigma_yy_c/tau', 'Sigma_zz_c/tau',
         'N1_c/tau', 'N2_c/tau', 'Pi_c/tau',
         'lambda_2', 'lambda_3', 'lambda_2_c', 'lambda_3_c', 'eta_n', 'eta_n_c',
         'I_v', 'mu', 'mu_h', 'mu_c', 'phi_core', 'gamma_dot_core', 'tau',
         'Sigma_xy/tau', 'Sigma_xy_c/tau', 'Pi_h/tau', 'N1_h/tau', 'gamma_dot_flow']
NAN = float('nan')


def div(a, b):
    return a / b if b != 0 and math.isfinite(b) else NAN


def slope(t):
    """Slope of a least-squares line from its sums (n, sum x, sum y, sum x^2, sum x y)."""
    den = t[0] * t[3] - t[1] ** 2
    return (t[0] * t[4] - t[1] * t[2]) / den if den > 0 else NAN


def quantities(m, shear_rate):
    """m: the 21 block-mean values (stress_hydro 5, stress_contact 5, phi_core, particle velocity
    fit 5, suspension flow fit 5)."""
    sh, sc = m[0:5], m[5:10]
    sp = sh + sc
    gd = slope(m[11:16])
    eta_r = 1.0 + div(sp[3], gd)
    eta_h = 1.0 + div(sh[3], gd)
    eta_c = div(sc[3], gd)
    tau = eta_r * gd
    p = -sc[1]
    q = [NAN] * len(NAMES)
    q[0:3] = [eta_r, eta_h, eta_c]
    q[3] = div(sp[0] - sp[1], tau)
    q[4] = div(sp[1] - sp[2], tau)
    q[5] = div(-sp[4] / 3.0, tau)
    q[6:9] = [div(x, tau) for x in sp[0:3]]
    q[9:12] = [div(x, tau) for x in sc[0:3]]
    q[12] = div(sc[0] - sc[1], tau)
    q[13] = div(sc[1] - sc[2], tau)
    q[14] = div(-sc[4] / 3.0, tau)
    if sp[0] != 0:
        q[15:17] = [sp[1] / sp[0], sp[2] / sp[0]]
    if sc[0] != 0:
        q[17:19] = [sc[1] / sc[0], sc[2] / sc[0]]
    q[19] = div(-sp[0], gd)
    q[20] = div(-sc[0], gd)
    if p > 0:
        q[21:25] = [gd / p, tau / p, eta_h * gd / p, eta_c * gd / p]
    q[25] = m[10]
    q[26] = gd / shear_rate
    q[27] = tau / shear_rate
    q[28] = div(sp[3], tau)
    q[29] = div(sc[3], tau)
    q[30] = div(-sh[4] / 3.0, tau)
    q[31] = div(sh[0] - sh[1], tau)
    q[32] = slope(m[16:21]) / shear_rate
    return np.array(q)


def load(outdir):
    """The series of a run, with its settings (attributes written by fdsusp); records still in
    series.parts/ (a running or killed run) included (scripts/series.py)."""
    names = ['step', 'time', 'core/stress_hydro', 'core/stress_contact', 'core/solid_fraction', 'core/velocity_fit',
             'core/flow_fit', 'core/shear_rate', 'pairs/references', 'pairs/shell', 'pairs/contact',
             'profiles/solid_fraction', 'profiles/momentum']
    try:
        s, attrs = series.read(outdir, names)
    except KeyError:
        raise SystemExit(f'{outdir}/series.h5 holds no core statistics: the run had no &rheology')
    a = {k: float(np.ravel(v)[0]) for k, v in attrs.items()}
    return a, s


def core_values(s):
    """Per record, the 21 core values in the order quantities() takes them."""
    return np.hstack([s['core/stress_hydro'], s['core/stress_contact'], s['core/solid_fraction'][:, None],
                      s['core/velocity_fit'], s['core/flow_fit']])


def with_window(a, discard_strain, average_strain, blocks):
    """The settings a with the averaging window of &rheology discard_strain, average_strain and
    blocks, in steps as src/runtime/params.F90 computes them (nint of strain / (|shear_rate| dt))."""
    per_step = abs(a['shear_rate']) * a['dt']
    a = dict(a)
    a['blocks'] = int(blocks)
    a['discard_step'] = math.floor(discard_strain / per_step + 0.5)
    a['block_steps'] = math.floor(average_strain / (blocks * per_step) + 0.5)
    if a['blocks'] < 1 or a['block_steps'] < 1:
        raise SystemExit('--window: blocks and average_strain/blocks must be at least one step')
    return a


def strain_windows(a, s, width, names):
    """The quantities names over successive windows of `width` strains from the start of the run
    (records on the series_every grid with strain in (k width, (k + 1) width]), each from the mean of
    its records as a block's: whether and how a run drifts. Returns {'width', 'strain_start', name: [...]}."""
    step = np.rint(s['step']).astype(np.int64)
    strain = s['time'] * abs(a['shear_rate'])
    values = core_values(s)
    on_grid = step % int(a['series_every']) == 0
    out = {'width': width, 'strain_start': []}
    out.update({n: [] for n in names})
    for k in range(int(math.ceil(strain.max() / width - 1e-9))):
        m = on_grid & (strain > k * width + 1e-9) & (strain <= (k + 1) * width + 1e-9)
        if not m.any():
            continue
        q = quantities(values[m].mean(axis=0), a['shear_rate'])
        out['strain_start'].append(k * width)
        for n in names:
            v = q[NAMES.index(n)]
            out[n].append(float(v) if math.isfinite(v) else None)
    return out


def as_json(a, summ):
    """A recomputed summary with the keys of fdsusp's summary.json (NaN as null)."""
    def clean(x):
        return [None if not math.isfinite(v) else float(v) for v in x]
    return {'program': 'scripts/rheology.py', 'complete': summ['blocks_complete'] == summ['blocks'],
            'blocks': summ['blocks'], 'blocks_complete': summ['blocks_complete'],
            'discard_step': int(a['discard_step']), 'block_steps': int(a['block_steps']),
            'last_step': summ['last_step'], 'records_per_block': summ['records_per_block'], 'core': [a['core_lo'], a['core_hi']], 'shear_rate': a['shear_rate'],
            'quantities': {n: {k: (v if math.isfinite(v) else None) for k, v in q.items()}
                           for n, q in summ['quantities'].items()},
            'profiles': {k: clean(v) for k, v in summ['profiles'].items()},
            'pair_distribution': {'r_outer': a['pair_radius'], 'r_contact': a['contact_radius'],
                                  **{k: clean(v) for k, v in summ['pair_distribution'].items()}}}


def summarise(a, s):
    """The summary as src/kernels/rheology.F90 computes it (see the module header there)."""
    step = np.rint(s['step']).astype(np.int64)
    blocks, discard, block_steps = int(a['blocks']), int(a['discard_step']), int(a['block_steps'])
    every = int(a['series_every'])
    last_step = int(step.max())
    block = np.where((step > discard) & (step % every == 0), (step - discard - 1) // block_steps, -1)
    block[block >= blocks] = -1
    values = core_values(s)
    records = np.array([np.count_nonzero(block == b) for b in range(blocks)])
    complete = 0
    for b in range(1, blocks + 1):
        if discard + b * block_steps <= last_step and records[b - 1] > 0:
            complete = b
    means = [values[block == b].sum(axis=0) / records[b] for b in range(complete)]
    value = quantities(np.mean(means, axis=0), a['shear_rate']) if complete > 0 else np.full(len(NAMES), NAN)
    error = np.full(len(NAMES), NAN)
    if complete > 1:
        per_block = np.array([quantities(m, a['shear_rate']) for m in means])
        error = per_block.std(axis=0, ddof=1) / math.sqrt(complete)
    inside = (block >= 0) & (block < complete)
    nrec = np.count_nonzero(inside)
    nbins = s['profiles/solid_fraction'].shape[1]
    nang = s['pairs/shell'].shape[1]
    y = (np.arange(nbins) + 0.5) * a['box_y'] / nbins
    theta = (np.arange(nang) + 0.5) * 2 * math.pi / nang
    if nrec > 0:
        phi_sum = s['profiles/solid_fraction'][inside].sum(axis=0)
        mom_sum = s['profiles/momentum'][inside].sum(axis=0)
        with np.errstate(invalid='ignore', divide='ignore'):
            velocity = np.where(phi_sum > 0, mom_sum / phi_sum, NAN)
        phi = phi_sum / nrec
        dtheta = 2 * math.pi / nang
        n_core = value[25] / (4.0 / 3.0 * math.pi * a['radius'] ** 3)
        refs = s['pairs/references'][inside].sum()
        shells = [(r ** 3 - (2 * a['radius']) ** 3) / 3.0 * dtheta * 2 * math.sin(0.5 * dtheta)
                  for r in (a['pair_radius'], a['contact_radius'])]
        g = s['pairs/shell'][inside].sum(axis=0) / (refs * n_core * shells[0])
        gc = s['pairs/contact'][inside].sum(axis=0) / (refs * n_core * shells[1])
    else:
        phi = velocity = np.full(nbins, NAN)
        g = gc = np.full(nang, NAN)
    return {'blocks': blocks, 'blocks_complete': complete, 'last_step': last_step,
            'records_per_block': [float(r) for r in records],
            'quantities': {n: {'value': v, 'error': e} for n, v, e in zip(NAMES, value, error)},
            'profiles': {'y': y, 'solid_fraction': phi, 'velocity': velocity},
            'pair_distribution': {'theta': theta, 'g': g, 'g_contact': gc}}


def differs(x, y, tol=1e-10):
    """Relative difference above tol; None (JSON null) equals NaN."""
    x = NAN if x is None else float(x)
    y = NAN if y is None else float(y)
    if math.isnan(x) or math.isnan(y):
        return not (math.isnan(x) and math.isnan(y))
    return abs(x - y) > tol * max(abs(x), abs(y), 1e-300)


def compare(ours, path):
    """Differences between our summary and the run's summary.json: a list of lines."""
    with open(path) as f:
        theirs = json.load(f)
    bad = []
    for key in ('blocks', 'blocks_complete', 'last_step'):
        if theirs[key] != ours[key]:
            bad.append(f'{key}: {theirs[key]} vs {ours[key]}')
    for n in NAMES:
        for part in ('value', 'error'):
            if differs(theirs['quantities'][n][part], ours['quantities'][n][part]):
                bad.append(f"{n} {part}: {theirs['quantities'][n][part]} vs {ours['quantities'][n][part]}")
    for group, keys in (('profiles', ('solid_fraction', 'velocity')), ('pair_distribution', ('g', 'g_contact'))):
        for k in keys:
            for i, (x, y) in enumerate(zip(theirs[group][k], ours[group][k])):
                if differs(x, y):
                    bad.append(f'{group}/{k}[{i}]: {x} vs {y}')
                    break
    return bad


def print_summary(outdir, summ):
    print(f"{outdir}: {summ['blocks_complete']} of {summ['blocks']} blocks complete (last step {summ['last_step']})")
    for n in NAMES:
        q = summ['quantities'][n]
        print(f"  {n:16s} {q['value']:13.5e} +- {q['error']:10.3e}")


def plots(runs, directory):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    os.makedirs(directory, exist_ok=True)
    for outdir, a, s, summ in runs:
        # the run's directory name (its parent's when fdsusp wrote into a directory called 'out')
        parts = os.path.normpath(os.path.abspath(outdir)).split(os.sep)
        name = parts[-2] if parts[-1] == 'out' and len(parts) > 1 else parts[-1]
        strain = s['time'] * abs(a['shear_rate'])
        fig, ax = plt.subplots(1, 3, figsize=(15, 4))
        gd = a['shear_rate']
        ax[0].plot(strain, s['core/stress_hydro'][:, 3] / gd, label=r'$\Sigma^h_{xy}$')
        ax[0].plot(strain, s['core/stress_contact'][:, 3] / gd, label=r'$\Sigma^c_{xy}$')
        for k, lab in ((0, 'xx'), (1, 'yy'), (2, 'zz')):
            ax[0].plot(strain, (s['core/stress_hydro'][:, k] + s['core/stress_contact'][:, k]) / gd,
                       label=rf'$\Sigma^p_{{{lab}}}$', lw=0.8)
        ax[0].axvline(a['discard_step'] * a['dt'] * abs(gd), color='k', ls=':')
        ax[0].set_xlabel(r'strain $\dot\gamma t$')
        ax[0].set_ylabel(r'core stress / $\eta\dot\gamma$')
        ax[0].legend(fontsize=7)
        p = summ['profiles']
        ax[1].plot(p['y'], p['solid_fraction'], label=r'$\langle\phi(y)\rangle$')
        ax[1].axvspan(a['core_lo'], a['core_hi'], color='0.9')
        ax[1].set_xlabel('y / a')
        ax[1].set_ylabel(r'$\phi$')
        ax1 = ax[1].twinx()
        ax1.plot(p['y'], p['velocity'], 'r', lw=0.8)
        ax1.set_ylabel(r'particle $u_x$ / $a\dot\gamma$', color='r')
        pd = summ['pair_distribution']
        # mirror symmetry (paper fig. 15): fold theta and theta + pi, plot against pi - theta
        n = len(pd['theta'])
        half = n // 2
        th = pd['theta'][:half]
        for key, lab in (('g', r'$g(r<r_{out},\theta)$'), ('g_contact', r'$g_c(\theta)$')):
            v = np.asarray(pd[key])
            folded = 0.5 * (v[:half] + v[half:2 * half])
            scale = np.nanmax(folded) if key == 'g_contact' and np.nanmax(folded) > 0 else 1.0
            ax[2].plot(math.pi - th, folded / scale, 'o-', ms=3,
                       label=lab + (' (scaled to max 1)' if scale != 1.0 else ''))
        ax[2].set_xlabel(r'$\pi - \theta$')
        ax[2].legend(fontsize=7)
        fig.suptitle(f"{name}: phi_core = {summ['quantities']['phi_core']['value']:.3f}, "
                     f"eta_r = {summ['quantities']['eta_r']['value']:.3f}")
        fig.tight_layout()
        fig.savefig(os.path.join(directory, f'{name}_run.png'), dpi=110)
        plt.close(fig)
    if len(runs) > 1:
        fig, ax = plt.subplots(1, 3, figsize=(15, 4))
        frictions = sorted({a.get('friction', 0.0) for _, a, _, _ in runs})
        for mu in frictions:
            sel = [summ for _, a, _, summ in runs if a.get('friction', 0.0) == mu]
            sel.sort(key=lambda z: z['quantities']['phi_core']['value'])
            phi = [z['quantities']['phi_core']['value'] for z in sel]
            for k, n in enumerate(('eta_r', 'N1/tau', 'N2/tau')):
                ax[k].errorbar(phi, [z['quantities'][n]['value'] for z in sel],
                               yerr=[z['quantities'][n]['error'] for z in sel], marker='o', capsize=3,
                               label=rf'$\mu_d$ = {mu:g}')
        phis = np.linspace(0.0, max(z['quantities']['phi_core']['value'] for _, _, _, z in runs), 50)
        ax[0].plot(phis, (1 - phis / 0.68) ** (-2.4 * 0.68), 'k--', lw=0.8,
                   label=r'$\eta_\infty$ fit of the paper (Krieger, 2.4, 0.68)')
        for k, n in enumerate(('eta_r', 'N1/tau', 'N2/tau')):
            ax[k].set_xlabel(r'$\phi_{core}$')
            ax[k].set_ylabel(n)
            ax[k].legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(directory, 'rheology_vs_phi.png'), dpi=110)
        plt.close(fig)


# Published fits the paper compares with (Gallier et al. 2014 §4.2-4.8), the constants as published:
# Zarraga, Hill & Leighton 2000 (J. Rheol. 44, 185): eta_r = exp(-2.34 phi) / (1 - phi/0.62)^3.
# Dai, Bertevas, Qi & Tanner 2013 (J. Rheol. 57, 493), 0.1 <= phi <= 0.45: N1/tau = -0.8 phi^3,
#   N2/tau = -4.4 phi^3.
# Morris & Boulay 1999 (J. Rheol. 43, 1213): eta_n = K_n (phi/phi_m)^2 / (1 - phi/phi_m)^2,
#   K_n = 0.75, phi_m = 0.68; the paper's fit of that form to its mu_d = 0.5 runs: 1.13, 0.58 (§4.7).
# Boyer, Guazzelli & Pouliquen 2011 (PRL 107, 188301): mu(I_v) = mu_1 + (mu_2 - mu_1)/(1 + I_0/I_v)
#   + I_v + 5/2 phi_m I_v^(1/2), phi(I_v) = phi_m / (1 + I_v^(1/2)); mu_1 = 0.32, mu_2 = 0.7,
#   I_0 = 0.005, phi_m = 0.585. The paper's eta_inf: Krieger-Dougherty, [eta] = 2.4, phi_m' = 0.68.
def zarraga_eta(phi):
    return np.exp(-2.34 * phi) / (1 - phi / 0.62) ** 3


def dai_normal(phi):
    return -0.8 * phi ** 3, -4.4 * phi ** 3


def morris_boulay_eta_n(phi, k_n=0.75, phi_m=0.68):
    return k_n * (phi / phi_m) ** 2 / (1 - phi / phi_m) ** 2


def boyer_mu(i_v, mu_1=0.32, mu_2=0.7, i_0=0.005, phi_m=0.585):
    return mu_1 + (mu_2 - mu_1) / (1 + i_0 / i_v) + i_v + 2.5 * phi_m * np.sqrt(i_v)


def boyer_phi(i_v, phi_m=0.585):
    return phi_m / (1 + np.sqrt(i_v))


def eta_inf(phi):
    return (1 - phi / 0.68) ** (-2.4 * 0.68)


def load_records(paths):
    """Recorded summaries: (label, run settings, quantities); only complete ones, and not the
    extensions of runs (their later windows are drawn by strain_figure)."""
    out = []
    for path in paths:
        with open(path) as f:
            s = json.load(f)
        if not s.get('complete') or 'run' not in s:
            print(f'{path}: not a complete recorded summary (no "run" object), skipped')
            continue
        if 'continues' in s['run']:
            continue
        out.append((os.path.basename(os.path.dirname(os.path.abspath(path))), s['run'], s['quantities']))
    return out


def stick_number(run):
    """dt gamma_dot a/((7/2) mu_d eps_bar h_r) (doc/CONTACT.md): above ~5 contacts that should stick
    slide. 0 without friction (no spring to stick)."""
    if run['friction'] <= 0:
        return 0.0
    return run['dt'] / (3.5 * run['friction'] * run['eps_bar'] * run['roughness'])


def setup_key(run):
    """What a run's set-up is apart from its friction and time step: runs with the same key form a
    sweep (the time step follows the friction, to keep the stick resolved)."""
    return (tuple(run['box']), run['cells_per_radius'], run['solid_fraction_bulk'], run['seed'],
            run['eps_bar'], run['roughness'])


def strain_figure(paths, directory):
    """friction_by_strain.png: eta_r, phi_core and N2/tau over successive strain windows of the
    recorded extensions (their "by_strain"), one line per run: whether a run's first window was
    steady."""
    runs = []
    for path in paths:
        with open(path) as f:
            s = json.load(f)
        if 'by_strain' in s and 'run' in s:
            runs.append((s['run']['continues'], s['run'], s['by_strain']))
    if not runs:
        return
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    os.makedirs(directory, exist_ok=True)
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    for label, run, b in runs:
        x = np.array(b['strain_start']) + 0.5 * b['width']
        for ax, name in zip(axes, ('eta_r', 'phi_core', 'N2/tau')):
            y = np.array([np.nan if v is None else v for v in b[name]])
            ax.plot(x, y, marker='.', label='%s (%d spheres)' % (label, run['spheres'] or 0))
    for ax, name in zip(axes, ('eta_r', 'phi_core', 'N2/tau')):
        ax.set_xlabel('strain (window of %g)' % runs[0][2]['width'])
        ax.set_ylabel(name)
        ax.axvline(runs[0][1]['strain_discarded'], color='grey', lw=0.8, ls=':')
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(directory, 'friction_by_strain.png'), dpi=110)
    plt.close(fig)


def record_figures(records, directory):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    os.makedirs(directory, exist_ok=True)
    frictions = sorted({r['friction'] for _, r, _ in records})
    colour = {mu: plt.cm.viridis(k / max(1, len(frictions) - 1)) for k, mu in enumerate(frictions)}

    def points(ax, name, scale=1.0, marker='o', filled=True, labelled=True):
        for mu in frictions:
            sel = [(r, q) for _, r, q in records if r['friction'] == mu]
            ax.errorbar([q['phi_core']['value'] for _, q in sel], [scale * q[name]['value'] for _, q in sel],
                        yerr=[abs(scale) * q[name]['error'] for _, q in sel], ls='none', marker=marker,
                        color=colour[mu], mfc=colour[mu] if filled else 'none', capsize=3,
                        label=rf'$\mu_d$ = {mu:g}' if labelled else None)

    phis = np.linspace(0.05, 0.5, 100)
    # figure 9 (and 10): eta_r, with eta_h as open symbols
    fig, ax = plt.subplots(figsize=(6, 4.5))
    points(ax, 'eta_r')
    points(ax, 'eta_h', marker='s', filled=False, labelled=False)
    ax.plot(phis, zarraga_eta(phis), 'k-', lw=0.8, label='Zarraga et al. (2000) fit')
    ax.plot(phis, eta_inf(phis), 'k--', lw=0.8, label=r'$\eta_\infty$ (paper eq. 4.19)')
    ax.set_yscale('log')
    ax.set_xlabel(r'$\phi_{core}$')
    ax.set_ylabel(r'$\eta_r$ (filled), $\eta^h$ (open squares)')
    ax.legend(fontsize=8)
    ax.set_title('relative viscosity (paper fig. 9, 10)', fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(directory, 'paper_fig9.png'), dpi=110)
    plt.close(fig)
    # figure 11: N1/tau, N2/tau
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    n1, n2 = dai_normal(phis)
    for k, (name, fit) in enumerate((('N1/tau', n1), ('N2/tau', n2))):
        points(ax[k], name)
        ax[k].plot(phis, fit, 'k-', lw=0.8, label='Dai et al. (2013) fit')
        ax[k].set_xlabel(r'$\phi_{core}$')
        ax[k].set_ylabel(name)
        ax[k].legend(fontsize=8)
    fig.suptitle('normal stress differences (paper fig. 11)', fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(directory, 'paper_fig11.png'), dpi=110)
    plt.close(fig)
    # figure 16: against mu_d, one line per set-up (dt aside) with three or more frictions; at each
    # mu_d the run of the smallest dt, drawn open where its stick number exceeds 5 (contacts that
    # should stick slide: a lower bound, doc/CONTACT.md)
    sweeps = {}
    for label, r, q in records:
        best = sweeps.setdefault(setup_key(r), {})
        if r['friction'] not in best or r['dt'] < best[r['friction']][0]['dt']:
            best[r['friction']] = (r, q)
    sweeps = {k: [(mu, r, q) for mu, (r, q) in sorted(v.items())] for k, v in sweeps.items() if len(v) >= 3}
    if sweeps:
        fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
        for key, v in sweeps.items():
            mu = np.array([z[0] for z in v])
            resolved = np.array([stick_number(z[1]) <= 5 for z in v])
            tag = '%gx%gx%g, a/D %d, bulk %.3g' % (key[0] + key[1:3])
            for a_, names in ((ax[0], (('eta_r', 'o'),)), (ax[1], (('N1/tau', 'o'), ('N2/tau', 's')))):
                for name, m in names:
                    val = np.array([z[2][name]['value'] for z in v])
                    err = np.array([z[2][name]['error'] for z in v])
                    line = a_.errorbar(mu, val, yerr=err, marker=m, capsize=3, mfc='none',
                                       label=(tag if name == 'eta_r' else f'{name}, {tag}'))
                    a_.plot(mu[resolved], val[resolved], m, color=line[0].get_color())
        ax[0].set_ylabel(r'$\eta_r$')
        ax[1].set_ylabel(r'$N_1/\tau$ (circles), $N_2/\tau$ (squares)')
        for a_ in ax:
            a_.set_xlabel(r'$\mu_d$')
            a_.legend(fontsize=7)
        fig.suptitle(r'friction sweep at $\phi_{bulk}$ = 0.4 (paper fig. 16); at each $\mu_d$ the smallest dt, '
                     'open: stick number > 5 (a lower bound)', fontsize=10)
        fig.tight_layout()
        fig.savefig(os.path.join(directory, 'paper_fig16.png'), dpi=110)
        plt.close(fig)
    # figures 20-22: normal viscosity; phi and mu against I_v = eta gamma_dot / Sigma_yy^c
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    points(ax[0], 'eta_n')
    ax[0].plot(phis, morris_boulay_eta_n(phis), 'k-', lw=0.8, label='Morris & Boulay (1999)')
    ax[0].plot(phis[phis < 0.5], morris_boulay_eta_n(phis[phis < 0.5], 1.13, 0.58), 'k--', lw=0.8,
               label=r'its form fitted by the paper to $\mu_d$ = 0.5 (1.13, 0.58)')
    ax[0].set_xlabel(r'$\phi_{core}$')
    ax[0].set_ylabel(r'$\eta_n^p = -\Sigma^p_{xx}/\eta\dot\gamma$')
    iv = np.logspace(-2, 2, 100)
    for mu in frictions:
        sel = [q for _, r, q in records if r['friction'] == mu]
        ax[1].plot([q['I_v']['value'] for q in sel], [q['phi_core']['value'] for q in sel], 'o',
                   color=colour[mu], label=rf'$\mu_d$ = {mu:g}')
        ax[2].errorbar([q['I_v']['value'] for q in sel], [q['mu']['value'] for q in sel],
                       yerr=[q['mu']['error'] for q in sel], ls='none', marker='o', color=colour[mu],
                       capsize=3, label=rf'$\mu_d$ = {mu:g}')
    ax[1].plot(iv, boyer_phi(iv), 'k-', lw=0.8, label='Boyer et al. (2011)')
    ax[2].plot(iv, boyer_mu(iv), 'k-', lw=0.8, label='Boyer et al. (2011)')
    for a_ in ax[1:]:
        a_.set_xscale('log')
        a_.set_xlabel(r'$I_v = \eta\dot\gamma/\Sigma^c_{yy}$')
    ax[1].set_ylabel(r'$\phi_{core}$')
    ax[2].set_ylabel(r'$\mu = \tau/\Sigma^c_{yy}$')
    ax[2].set_yscale('log')
    for a_ in ax:
        a_.legend(fontsize=8)
    fig.suptitle('normal viscosity and the mu(I_v) rheology (paper figs. 20-22)', fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(directory, 'paper_fig20_22.png'), dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('outdirs', nargs='*')
    ap.add_argument('--plots', metavar='DIR')
    ap.add_argument('--compare', action='store_true')
    ap.add_argument('--records', nargs='+', metavar='SUMMARY', help='recorded summary.json files')
    ap.add_argument('--window', nargs=3, type=float, metavar=('DISCARD', 'AVERAGE', 'BLOCKS'),
                    help='strains discarded and averaged, and blocks, instead of the run\'s &rheology')
    ap.add_argument('--json', metavar='FILE', help='write the recomputed summary (one OUTDIR)')
    args = ap.parse_args()
    if args.json and len(args.outdirs) != 1:
        ap.error('--json needs exactly one OUTDIR')
    if args.records:
        if not args.plots:
            ap.error('--records needs --plots DIR')
        record_figures(load_records(args.records), args.plots)
        strain_figure(args.records, args.plots)
        return 0
    if not args.outdirs:
        ap.error('give run output directories or --records')
    runs = []
    status = 0
    for outdir in args.outdirs:
        a, s = load(outdir)
        if args.window:
            a = with_window(a, *args.window)
        summ = summarise(a, s)
        if args.json:
            with open(args.json, 'w') as f:
                json.dump(as_json(a, summ), f, indent=1)
                f.write('\n')
        print_summary(outdir, summ)
        if args.compare:
            bad = compare(summ, os.path.join(outdir, 'summary.json'))
            if bad:
                status = 1
                print(f'  summary.json differs ({len(bad)}):', *bad[:10], sep='\n    ')
            else:
                print('  summary.json agrees to 1e-10')
        runs.append((outdir, a, s, summ))
    if args.plots:
        plots(runs, args.plots)
    return status


if __name__ == '__main__':
    sys.exit(main())
