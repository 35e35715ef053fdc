"""Rheology against phi of the 1:1.4 mixture (50/50 by volume) and of equal spheres, frictionless and
mu_d 0.5, lubrication dynamics in a Lees-Edwards cube of 12a (decks doc/data/polydisperse/curves;
README.md there, section "Curves").

    PYTHONPATH=python python3 doc/data/polydisperse/summarise_curves.py --collect
        copies each run's out/polydisperse/curves/NAME/summary.json to curves/NAME.summary.json and
        writes curves/NAME.status.json from its log (out/polydisperse/curves/NAME.log): spheres,
        species counts, phi, strain reached, wall time, largest overlap, and how it ended
        (complete, stopped by the overlap guard, refused, stopped by max_wall_hours)
    PYTHONPATH=python python3 doc/data/polydisperse/summarise_curves.py
        the table (curves_table.json) and doc/figures/mixture_rheology.png from the committed files
"""
import glob, json, os, re, shutil, sys

HERE = os.path.dirname(os.path.abspath(__file__))
CURVES = os.path.join(HERE, 'curves')
ROOT = os.path.abspath(os.path.join(HERE, '..', '..', '..'))
OUT = os.path.join(ROOT, 'out', 'polydisperse', 'curves')
FIG = os.path.join(ROOT, 'doc', 'figures', 'mixture_rheology.png')
QUANTITIES = ('eta_r', 'N1/tau', 'N2/tau', 'Pi/tau', 'eta_h', 'eta_c', 'phi_core')

# Published data for the comparison (README.md "Curves", "Published data"). No mixture data set
# with numbers could be read (the stored copies of Mari et al. 2014, Singh et al. 2018, Pednekar
# et al. 2018 hold their abstracts only); drawn are the equal-sphere fits of fdsusp.references
# (constants as published): Zarraga, Hill & Leighton 2000 and Boyer, Guazzelli & Pouliquen 2011
# (experiments, eta_r), Dai, Bertevas, Qi & Tanner 2013 (experiments, N1/tau and N2/tau, phi <= 0.45).
def published():
    import numpy as np
    from fdsusp import references as ref
    phi = np.linspace(0.35, 0.58, 47)
    iv = (0.585 / phi[phi < 0.575] - 1) ** 2
    dphi = np.linspace(0.35, 0.45, 11)
    n1, n2 = ref.dai_normal(dphi)
    return [
        dict(quantity='eta_r', label='Zarraga et al. 2000 (experiment, equal spheres)', style='k:',
             points=[[float(x), float(y)] for x, y in zip(phi, ref.zarraga_eta(phi))]),
        dict(quantity='eta_r', label='Boyer et al. 2011 (experiment, equal spheres, phi_m 0.585)', style='k-.',
             points=[[float(x), float(y)] for x, y in zip(phi[phi < 0.575], ref.boyer_mu(iv) / iv)]),
        dict(quantity='N1/tau', label='Dai et al. 2013 (experiment, equal spheres)', style='k:',
             points=[[float(x), float(y)] for x, y in zip(dphi, n1)]),
        dict(quantity='N2/tau', label='Dai et al. 2013 (experiment, equal spheres)', style='k:',
             points=[[float(x), float(y)] for x, y in zip(dphi, n2)]),
    ]


def deck_values(name):
    text = open(os.path.join(CURVES, name + '.nml')).read()
    dt = float(re.search(r'dt\s*=\s*([0-9.eE+-]+)', text).group(1))
    steps = int(re.search(r'steps\s*=\s*(\d+)', text).group(1))
    mu = float(re.search(r'friction\s*=\s*([0-9.eE+-]+)', text).group(1))
    phi = float(re.search(r'solid_fraction\s*=\s*([0-9.eE+-]+)', text).group(1))
    eps_bar = float(re.search(r'eps_bar\s*=\s*([0-9.eE+-]+)', text).group(1))
    seed = int(re.search(r'seed\s*=\s*(\d+)', text).group(1))
    species = 'mixture' if 'volume_share' in text else 'equal'
    return dict(dt=dt, steps=steps, mu=mu, phi_deck=phi, species=species, eps_bar=eps_bar, seed=seed)


def collect(name):
    """Status of one run from its log (all its segments: a continued run appends to it)."""
    log_file = os.path.join(OUT, name + '.log')
    if not os.path.exists(log_file):
        return None
    log = open(log_file, errors='replace').read()
    st = dict(name=name, **deck_values(name))
    m = re.search(r'packing: (\d+) spheres, phi =\s*([0-9.]+)', log)
    if m:
        st['spheres'], st['phi_packed'] = int(m.group(1)), float(m.group(2))
    m = re.search(r'spheres per species \(&particles radius\):\s*([0-9, ]+)', log)
    if m:
        st['species_counts'] = [int(x) for x in m.group(1).replace(',', ' ').split()]
    walls = [float(x) for x in re.findall(r'^wall time\s+([0-9.]+) s', log, re.M)]
    st['wall_seconds'] = sum(walls) if walls else None
    if not walls:   # stopped before its end: the last progress line's wall time
        prog = [float(x) for x in re.findall(r'^step\s+\d+\s+strain\s+[0-9.]+\s+wall\s+([0-9.]+) s', log, re.M)]
        st['wall_seconds'] = prog[-1] if prog else None
    steps_run = [int(x) for x in re.findall(r'^steps run:\s*(\d+)', log, re.M)]
    per_step = [float(x) for x in re.findall(r'wall time per step:\s*([0-9.eE+-]+) s', log)]
    if steps_run and per_step:
        st['wall_seconds_stepping'] = sum(n * t for n, t in zip(steps_run, per_step))
    steps = [int(x) for x in re.findall(r'^step\s+(\d+)\s+strain', log, re.M)]
    m_fin = re.findall(r'^finished at step (\d+)', log, re.M)
    last = max([int(x) for x in m_fin] + steps + [0])
    st['last_step'] = last
    st['strain_reached'] = last * st['dt']
    ov = re.findall(r'largest overlap \|delta\'\| over this run\s+([0-9.eE+-]+) h_r', log)
    if ov:
        st['largest_overlap_h_r'] = max(float(x) for x in ov)
    refusal = [l for l in log.splitlines() if 'jam in shear' in l or 'refus' in l.lower()]
    guard = [l for l in log.splitlines() if 'fatal' in l and 'overlap' in l and 'exceeds' in l]
    warn = [l.strip() for l in log.splitlines() if l.startswith('fdsusp: warning')]
    if warn:
        st['warnings'] = sorted(set(warn))
    summ = os.path.join(OUT, name, 'summary.json')
    complete = False
    if os.path.exists(summ):
        s = json.load(open(summ))
        complete = bool(s.get('complete'))
        shutil.copy(summ, os.path.join(CURVES, name + '.summary.json'))
    try:   # Steinhardt Q6 of all bonds (series.h5 structure/q6): the order of the averaging window
        from fdsusp import series
        ser, _ = series.read(os.path.join(OUT, name), ['time', 'structure/q6'])
        t, q6 = ser['time'], ser['structure/q6']
        disc = s['discard_step'] * st['dt'] if os.path.exists(summ) else 0.0
        if (t < 1).any():
            st['q6_first_strain'] = float(q6[t < 1].mean())
        if (t >= disc).any():
            st['q6_window'] = float(q6[t >= disc].mean())
    except Exception as err:   # no series (refused) or no Q6 columns
        st['q6_note'] = str(err)[:200]
    if complete:
        st['ended'] = 'complete'
    elif os.path.exists(os.path.join(OUT, name, 'failed_state.h5')) or guard:
        st['ended'] = 'stopped by the overlap guard'
        st['message'] = guard[-1].strip() if guard else ''
        m = re.search(r'at step\s+(\d+)', st['message'])
        if m:
            st['stop_step'] = int(m.group(1))
            st['strain_reached'] = int(m.group(1)) * st['dt']
    elif refusal and not steps:
        st['ended'] = 'refused'
        st['message'] = ' '.join(l.strip() for l in refusal)
    else:
        st['ended'] = 'unfinished (max_wall_hours or killed): continue with -continue'
    json.dump(st, open(os.path.join(CURVES, name + '.status.json'), 'w'), indent=1)
    return st


def table():
    rows = []
    for f in sorted(glob.glob(os.path.join(CURVES, '*.status.json'))):
        st = json.load(open(f))
        row = dict(st)
        sf = os.path.join(CURVES, st['name'] + '.summary.json')
        if os.path.exists(sf):
            s = json.load(open(sf))
            row['blocks_complete'] = s['blocks_complete']
            row['discard_strain'] = s['discard_step'] * st['dt']
            row['average_strain'] = s['blocks'] * s['block_steps'] * st['dt']
            row['complete'] = s['complete']
            for q in QUANTITIES:
                if q in s['quantities']:
                    row[q] = s['quantities'][q]
        if row.get('wall_seconds_stepping') and row.get('strain_reached'):
            row['wall_seconds_per_strain'] = row['wall_seconds_stepping'] / row['strain_reached']
        rows.append(row)
    rows.sort(key=lambda r: (r['species'] != 'mixture', r['mu'], r['phi_deck'], r['eps_bar'] != 0.015,
                             r.get('seed', 3)))
    return rows


def fmt(q):
    if not q:
        return ''
    return f"{q['value']:.3g} +- {q['error']:.2g}"


def markdown(rows):
    head = ('| species | mu_d | phi (deck / in run) | N (small, large) | strains (discarded + averaged) | eta_r | N1/tau | '
            'N2/tau | Pi/tau | Q6 | wall time (s/strain) | ended |')
    lines = [head, '|' + '---|' * head.count('|')[:-1] if False else '|---|---|---|---|---|---|---|---|---|---|---|---|']
    for r in rows:
        n = str(r.get('spheres', ''))
        if r.get('species_counts'):
            n += ' (' + ', '.join(str(c) for c in r['species_counts']) + ')'
        phi = f"{r['phi_deck']:.2f} / {r.get('phi_packed', float('nan')):.4f}"
        if r.get('complete'):
            strains = f"{r['discard_strain']:g} + {r['average_strain']:g}"
        else:
            strains = f"{r.get('strain_reached', 0):.2f} reached"
        wall = r.get('wall_seconds')
        ps = r.get('wall_seconds_per_strain')
        wtxt = f"{wall:.0f} ({ps:.0f})" if wall and ps else ''
        ended = r['ended'] if r['ended'] != 'complete' else ''
        if r['eps_bar'] != 0.015:
            ended = (ended + '; ' if ended else '') + f"eps_bar {r['eps_bar']:g}, dt {r['dt']:g}"
        if r.get('seed', 3) != 3:
            ended = (ended + '; ' if ended else '') + f"seed {r['seed']}"
        if r.get('complete'):
            vals = [fmt(r.get(q)) for q in ('eta_r', 'N1/tau', 'N2/tau', 'Pi/tau')]
        else:
            vals = ['', '', '', '']
        q6 = f"{r['q6_window']:.3f}" if r.get('complete') and 'q6_window' in r else ''
        lines.append(f"| {r['species']} | {r['mu']:g} | {phi} | {n} | {strains} | " + ' | '.join(vals) +
                     f" | {q6} | {wtxt} | {ended} |")
    return '\n'.join(lines)


def figure(rows):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 2, figsize=(10, 8))
    style = {('mixture', 0.0): ('C0', 'o', '-'), ('mixture', 0.5): ('C1', 's', '-'),
             ('equal', 0.0): ('C0', 'o', '--'), ('equal', 0.5): ('C1', 's', '--')}
    for ax, q, lab in zip(axes.flat, ('eta_r', 'N1/tau', 'N2/tau', 'Pi/tau'),
                          (r'$\eta_r$', r'$N_1/\tau$', r'$N_2/\tau$', r'$\Pi/\tau$')):
        for (sp, mu), (c, mk, ls) in style.items():
            sel = [r for r in rows if r['species'] == sp and r['mu'] == mu and r.get('complete') and q in r
                   and r['eps_bar'] == 0.015 and r.get('seed', 3) == 3]
            other = [r for r in rows if r['species'] == sp and r['mu'] == mu and r.get('complete') and q in r
                     and (r['eps_bar'] != 0.015 or r.get('seed', 3) != 3)]
            labelled = set()
            for r in other:
                what = f"eps_bar {r['eps_bar']:g}" if r['eps_bar'] != 0.015 else f"seed {r['seed']}"
                # one legend entry per kind of extra run (the other packings share one)
                label = f"{'mixture' if sp == 'mixture' else 'equal'}, mu_d {mu:g}, {what}"
                ax.errorbar([r['phi_core']['value']], [r[q]['value']], yerr=[r[q]['error']], color=c,
                            marker='*' if r['eps_bar'] != 0.015 else 'x', ms=9, ls='none', capsize=3,
                            label=None if label in labelled else label)
                labelled.add(label)
            if not sel:
                continue
            x = [r['phi_core']['value'] for r in sel]
            y = [r[q]['value'] for r in sel]
            e = [r[q]['error'] for r in sel]
            name = ('1:1.4 mixture' if sp == 'mixture' else 'equal spheres') + f', $\\mu_d$ = {mu:g}'
            ax.errorbar(x, y, yerr=e, color=c, marker=mk, ls=ls, mfc='none' if sp == 'equal' else c,
                        capsize=3, label=name)
            # where a denser run of the same curve did not flow: mark it on the axis
            stopped = [r for r in rows if r['species'] == sp and r['mu'] == mu and not r.get('complete')
                       and r['ended'] != 'unfinished (max_wall_hours or killed): continue with -continue']
            for r in stopped:
                if q == 'eta_r':
                    ax.axvline(r.get('phi_packed', r['phi_deck']), color=c, ls=ls, lw=0.6, alpha=0.6)
        for p in published():
            if p['quantity'] == q:
                ax.plot([v[0] for v in p['points']], [v[1] for v in p['points']], p['style'], lw=1,
                        label=p['label'])
        if q == 'eta_r':
            ax.set_yscale('log')
        ax.set_xlabel(r'$\phi$ (in the run)')
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    for ax in axes.flat[:3]:
        ax.legend(fontsize=6)
    fig.suptitle('Lubrication dynamics, Lees-Edwards cube 12a, rough spheres (eps_r 5e-3, eps_bar 0.015), '
                 'strains discarded + averaged: 2 + 6 (mu_d 0), 1.5 + 4.5 (mu_d 0.5)\nthin vertical lines: runs that did not flow '
                 '(refused or stopped by the overlap guard)', fontsize=8)
    fig.tight_layout()
    fig.savefig(FIG, dpi=100)


if __name__ == '__main__':
    if '--collect' in sys.argv:
        names = open(os.path.join(CURVES, 'queue.txt')).read().split()
        for n in names:
            st = collect(n)
            if st:
                print(n, st['ended'], f"strain {st.get('strain_reached', 0):.2f}", st.get('wall_seconds'))
        sys.exit(0)
    rows = table()
    json.dump({'runs': rows, 'published': published()}, open(os.path.join(HERE, 'curves_table.json'), 'w'), indent=1)
    print(markdown(rows))
    figure(rows)
