"""The figures of fdsusp (matplotlib, Agg backend): the rheology per run and across runs from
summaries recomputed by fdsusp.rheology, the paper's comparisons from recorded summaries, and the
pieces the speed-accuracy and pair scripts draw with.

    run_figures(runs, directory)        runs: [(outdir, a, s, summ)] (fdsusp.rheology load, summarise)
    record_figures(records, directory)  records: fdsusp.rheology.load_records(paths)
    strain_figure(paths, directory)     the "by_strain" windows of recorded extensions
    plot_front(rows, path, ...)         error against cost with the Pareto front (scripts/tradeoff.py,
                                        tradeoff_pair.py)
    theta_axes(axes, fontsize)          the frame of the pair's N1*, N2* against theta panels
"""
import json
import math
import os

import numpy as np

from .references import boyer_mu, boyer_phi, dai_normal, eta_inf, morris_boulay_eta_n, zarraga_eta
from .rheology import setup_key, stick_number


def run_figures(runs, directory):
    """Per run: <name>_run.png (core stress against strain, phi(y) and u_x(y), g(theta) and
    g_c(theta)); for a mixture also <name>_species.png (species_figure); over two runs or more: rheology_vs_phi.png (eta_r, N1/tau, N2/tau against phi_core,
    one series per friction coefficient)."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    os.makedirs(directory, exist_ok=True)
    for outdir, a, s, summ in runs:
        # the run's directory name (its parent's when fdsusp wrote into a directory called 'out')
        parts = os.path.normpath(os.path.abspath(outdir)).split(os.sep)
        name = parts[-2] if parts[-1] == 'out' and len(parts) > 1 else parts[-1]
        strain = s['time'] * abs(a['shear_rate'])
        # a fourth panel for the crystalline order when the run measured it (doc/RHEOLOGY.md "Order")
        order = 'structure/q6' in s
        fig, ax = plt.subplots(1, 4 if order else 3, figsize=(20 if order else 15, 4))
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
        if order:
            ax[3].plot(strain, s['structure/q6'], label=r'$Q_6$ (all bonds)')
            ax[3].plot(strain, s['structure/q6_local'], lw=0.8, label=r'mean local $q_6$')
            ax[3].axhline(0.5745, color='k', ls=':', lw=0.8, label='fcc crystal')
            ax[3].set_xlabel(r'strain $\dot\gamma t$')
            ax[3].set_ylabel('bond-orientational order')
            ax[3].set_ylim(0.0, 0.65)
            ax[3].legend(fontsize=7)
        fig.suptitle(f"{name}: phi_core = {summ['quantities']['phi_core']['value']:.3f}, "
                     f"eta_r = {summ['quantities']['eta_r']['value']:.3f}")
        fig.tight_layout()
        fig.savefig(os.path.join(directory, f'{name}_run.png'), dpi=110)
        plt.close(fig)
        if 'species' in summ:
            species_figure(plt, name, a, summ, directory)
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
        ax[0].plot(phis, eta_inf(phis), 'k--', lw=0.8,
                   label=r'$\eta_\infty$ fit of the paper (Krieger, 2.4, 0.68)')
        for k, n in enumerate(('eta_r', 'N1/tau', 'N2/tau')):
            ax[k].set_xlabel(r'$\phi_{core}$')
            ax[k].set_ylabel(n)
            ax[k].legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(directory, 'rheology_vs_phi.png'), dpi=110)
        plt.close(fig)


def species_figure(plt, name, a, summ, directory):
    """A mixture's <name>_species.png (doc/RHEOLOGY.md "Per species"): phi_s(y) of each species with
    the pooled phi(y) (segregation across the gap), the partial pair distributions g_ab(r) with
    their block errors, and each species' share of eta_r - 1, N1/tau, N2/tau, Pi/tau."""
    sp = summ['species']
    radius = sp['radius']
    ns = len(radius)
    fig, ax = plt.subplots(1, 3, figsize=(16, 4.2))
    p = summ['profiles']
    ax[0].plot(p['y'], p['solid_fraction'], 'k', lw=1.2, label=r'$\phi(y)$, all')
    for j in range(ns):
        ax[0].plot(p['y'], sp['profiles']['solid_fraction'][j], label=rf'$\phi_{j + 1}(y)$, a = {radius[j]:g}')
    if a['core_lo'] > 0:
        ax[0].axvspan(a['core_lo'], a['core_hi'], color='0.92')
    ax[0].set_xlabel('y / a')
    ax[0].set_ylabel('volume fraction')
    ax[0].legend(fontsize=7)
    pd = sp['pair_distribution']
    r = np.asarray(pd['r'], dtype=float)
    g = np.asarray(pd['g'], dtype=float)
    ge = np.asarray(pd['g_error'], dtype=float)
    for i in range(ns):
        for j in range(i, ns):
            line, = ax[1].plot(r, g[i, j], lw=1, label=rf'$g_{{{i + 1}{j + 1}}}(r)$')
            ax[1].fill_between(r, g[i, j] - ge[i, j], g[i, j] + ge[i, j], color=line.get_color(), alpha=0.25, lw=0)
            ax[1].axvline(radius[i] + radius[j], color=line.get_color(), ls=':', lw=0.8)
    ax[1].axhline(1.0, color='k', lw=0.6)
    ax[1].set_xlabel('r / a (a the smallest radius; dotted: contact)')
    ax[1].set_ylabel('partial pair distribution')
    ax[1].legend(fontsize=7)
    names = ['eta_r-1', 'N1/tau', 'N2/tau', 'Pi/tau']
    x = np.arange(len(names))
    width = 0.8 / ns
    for j in range(ns):
        ax[2].bar(x + (j - (ns - 1) / 2) * width, [sp['quantities'][n]['value'][j] for n in names], width,
                  yerr=[sp['quantities'][n]['error'][j] for n in names], capsize=3, label=f'a = {radius[j]:g}')
    ax[2].set_xticks(x)
    ax[2].set_xticklabels(names)
    ax[2].axhline(0.0, color='k', lw=0.6)
    ax[2].set_ylabel('share of the particle stress')
    ax[2].legend(fontsize=7)
    fig.suptitle(f'{name}: per species (shares add up to the pooled values)')
    fig.tight_layout()
    fig.savefig(os.path.join(directory, f'{name}_species.png'), dpi=110)
    plt.close(fig)


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
    """paper_fig9.png, paper_fig11.png, paper_fig16.png (sweeps of three frictions or more) and
    paper_fig20_22.png from recorded summaries (scripts/rheology.py --records)."""
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


def pareto(points):
    """Indices of the points no other point beats in both cost and error."""
    front = []
    for i, (c, e) in enumerate(points):
        if not any((c2 <= c and e2 <= e) and (c2 < c or e2 < e) for c2, e2 in points):
            front.append(i)
    return sorted(front, key=lambda i: points[i][0])


def plot_front(rows, path, cost, markers, xlabel, title, floor=1e-5, default_run=None, base_run=None, base_label=None,
               ylabel=None, reference_title=None, defaults=()):
    """Two panels of error against cost, one marker and colour per knob. Left: each knob's settings
    against that knob's finest (error_knob), each labelled, the finest itself left out (its error is
    0 by construction). Right: every setting against the reference (error), the Pareto front over
    the distinct configurations, and only the front's points labelled, each run once (base_run, which
    several knobs share, as base_label). Each knob's default setting is ringed on the left, the run
    of the default configuration (default_run) on the right (defaults: the labels of the knobs'
    default settings, each ringed on the left); errors below floor are drawn at floor
    (log axis). Rows without error_knob (the pair test, whose every error is against exact theory)
    get the right panel alone, with ylabel and reference_title."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    per_knob = all('error_knob' in r for r in rows)
    fig, axes = plt.subplots(1, 2 if per_knob else 1, figsize=(14.5 if per_knob else 9, 5.5), sharey=True,
                             squeeze=False)
    axes = axes[0]
    colours = dict(zip(markers, ['C%d' % i for i in range(len(markers))]))

    def draw(ax, key, labelled, ringed):
        placed = []                     # the labels so far, (x, y) of their points
        for knob, marker in markers.items():
            pts = [r for r in rows if r['knob'] == knob and r[key] is not None
                   and not (key == 'error_knob' and r['label'] == r['finest'])]
            for i, r in enumerate(pts):
                x, y = r[cost], max(r[key], floor)
                ax.scatter([x], [y], marker=marker, color=colours[knob], s=45,
                           label=knob if i == 0 else None, zorder=3)
                if ringed(r):
                    ax.scatter([x], [y], marker='o', s=220, facecolors='none', edgecolors='k', lw=1, zorder=2)
                text = labelled(r)
                if text:
                    # above its point, or below when a label already sits near it (within ~15 % in
                    # cost and a factor 1.6 in error), so that neighbours do not overlap
                    near = any(abs(math.log(x / px)) < 0.15 and abs(math.log(y / py)) < 0.5 for px, py in placed) \
                        or r['name'] == base_run          # (its long label would cross the default's ring)
                    placed.append((x, y))
                    ax.annotate(text, (x, y), fontsize=7, color=colours[knob],
                                xytext=(5, -11 if near else 6), textcoords='offset points')
        ax.set_xscale('log')
        ax.set_yscale('log')
        ax.set_xlabel(xlabel)
        ax.grid(True, which='major', lw=0.3)

    if per_knob:
        draw(axes[0], 'error_knob', lambda r: r['label'], lambda r: r['label'] in defaults)
        axes[0].set_ylabel('|eta_r - eta_r(finest)| / eta_r(finest)')
        axes[0].set_title("each knob against its own finest setting", fontsize=10)
    else:
        axes[0].set_ylabel(ylabel or 'error')
    pts = list({r['name']: r for r in rows if r['knob'] in markers and r['error'] is not None}.values())
    front = pareto([(r[cost], max(r['error'], floor)) for r in pts])
    on_front = {pts[i]['name'] for i in front}
    # one label per distinct run on the front (the base is shared by the grid, dt, lubrication and
    # model knobs: labelled once as such)
    named = set()

    def front_label(r):
        if r['name'] not in on_front or r['name'] in named:
            return None
        named.add(r['name'])
        return base_label if r['name'] == base_run and base_label else r['label']
    draw(axes[-1], 'error', front_label, lambda r: r['name'] == default_run)
    axes[-1].plot([pts[i][cost] for i in front], [max(pts[i]['error'], floor) for i in front], 'k--', lw=1,
                 label='Pareto front')
    axes[-1].set_title(reference_title or 'total error against the reference (finest grid, dt, tolerance)',
                       fontsize=10)
    axes[-1].scatter([], [], marker='o', s=220, facecolors='none', edgecolors='k', label="the code's default")
    axes[-1].legend(fontsize=8, loc='center left', bbox_to_anchor=(1.01, 0.5))
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fig.savefig(path, dpi=120)


def theta_axes(axes, fontsize):
    """Frame the N1*, N2* against theta panels of the pair figures (scripts/plot_pair.py,
    scripts/pair_dns.py): the line theta = pi/2 splits compression from extension."""
    for ax, q in zip(axes, ("N_1^*", "N_2^*")):
        ax.axhline(0, color="0.6", lw=0.5)
        ax.axvline(np.pi / 2, color="0.6", lw=0.5, ls=":")
        ax.set_xlim(0, np.pi)
        ax.set_xlabel(r"$\theta$ (rad, from $+x$)")
        ax.set_ylabel("$%s$" % q)
        ax.legend(fontsize=fontsize)
