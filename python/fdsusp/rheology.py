"""The rheology of a run's core region from its series (doc/RHEOLOGY.md), as src/kernels/rheology.F90
computes it: records on the series_every grid after discard_step, `blocks` blocks of block_steps
steps, quantities evaluated on the block means; value from the mean of the block means, error =
standard deviation over the complete blocks (ddof 1) / sqrt(blocks). No plotting here (fdsusp.plots).

    from fdsusp import rheology
    a, s = rheology.load('out/demo')              # settings, series (fdsusp.series.read)
    summ = rheology.summarise(a, s)               # or summarise(with_window(a, 2, 20, 5), s)
    summ['quantities']['eta_r']                   # {'value': ..., 'error': ...}
    rheology.compare(summ, 'out/demo/summary.json')   # [] when the program agrees to 1e-10
    summ['species']                               # a mixture's (doc/RHEOLOGY.md "Per species"):
                                                  # shares of the quantities, phi_s(y), g_ab(r)
"""
import json
import math
import os

import numpy as np

from . import series


class NoRheology(ValueError):
    """The run's series holds no core statistics (it had no &rheology)."""


# order and definitions as mod_rheology::rheo_quantities
NAMES = ['eta_r', 'eta_h', 'eta_c', 'N1/tau', 'N2/tau', 'Pi/tau',
         'Sigma_xx/tau', 'Sigma_yy/tau', 'Sigma_zz/tau', 'Sigma_xx_c/tau', 'Sigma_yy_c/tau', 'Sigma_zz_c/tau',
         'N1_c/tau', 'N2_c/tau', 'Pi_c/tau',
         'lambda_2', 'lambda_3', 'lambda_2_c', 'lambda_3_c', 'eta_n', 'eta_n_c',
         'I_v', 'mu', 'mu_h', 'mu_c', 'phi_core', 'gamma_dot_core', 'tau',
         'Sigma_xy/tau', 'Sigma_xy_c/tau', 'Pi_h/tau', 'N1_h/tau', 'gamma_dot_flow']


# a mixture's per-species shares of the pooled quantities, as mod_rheology::rheo_species_quantities
SPECIES_NAMES = ['eta_r-1', 'eta_h-1', 'eta_c', 'N1/tau', 'N2/tau', 'Pi/tau', 'N1_h/tau', 'N2_h/tau', 'Pi_h/tau',
                 'N1_c/tau', 'N2_c/tau', 'Pi_c/tau', 'phi_core']
# a mixture's per-species series columns (doc/RHEOLOGY.md "Per species")
SPECIES_COLUMNS = ['species/stress_hydro', 'species/stress_contact', 'species/solid_fraction', 'species/references',
                   'species/profile_solid_fraction', 'species/pair_counts', 'species/pair_volumes']

NAN = float('nan')


def div(a, b):
    return a / b if b != 0 and math.isfinite(b) else NAN


def slope(t):
    """Slope of a least-squares line from its sums (n, sum x, sum y, sum x^2, sum x y)."""
    den = t[0] * t[3] - t[1] ** 2
    return (t[0] * t[4] - t[1] * t[2]) / den if den > 0 else NAN


def quantities(m, shear_rate, fixed_rate=None):
    """m: the 21 block-mean values (stress_hydro 5, stress_contact 5, phi_core, particle velocity
    fit 5, suspension flow fit 5). fixed_rate: the rate the stresses are divided by instead of the
    measured core rate (a protocol whose rate varies: |reference rate|, doc/RHEOLOGY.md "Protocols")."""
    sh, sc = m[0:5], m[5:10]
    sp = sh + sc
    gd = slope(m[11:16]) if fixed_rate is None else fixed_rate
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
    q[26] = slope(m[11:16]) / shear_rate   # measured, also under a fixed_rate
    q[27] = tau / shear_rate
    q[28] = div(sp[3], tau)
    q[29] = div(sc[3], tau)
    q[30] = div(-sh[4] / 3.0, tau)
    q[31] = div(sh[0] - sh[1], tau)
    q[32] = slope(m[16:21]) / shear_rate
    return np.array(q)


def _fixed_rate(a):
    """|reference rate| when the run's rate varies (series attribute shear_protocol: a reversal or an
    oscillation; shear_control 2: stress control), else None: the summary's stresses are then over
    it (doc/RHEOLOGY.md "Protocols")."""
    varies = a.get('shear_protocol', 1) > 1 or a.get('shear_control', 1) == 2
    return abs(a['shear_rate']) if varies else None


def species_quantities(m, ms):
    """One species' shares of the pooled quantities: m the 21 pooled (block-)mean values, ms the
    species' 11 (stress_hydro 5, stress_contact 5, phi_core,s); stresses over the pooled
    gamma_dot_core and tau, so that the species' shares add up to the pooled eta_r - 1, N1/tau, ..."""
    gd = slope(m[11:16])
    tau = (1.0 + (m[3] + m[8]) / gd) * gd
    sh, sc = np.asarray(ms[0:5]), np.asarray(ms[5:10])
    sp = sh + sc
    q = [sp[3] / gd, sh[3] / gd, sc[3] / gd]
    for t in (sp, sh, sc):
        q += [(t[0] - t[1]) / tau, (t[1] - t[2]) / tau, -t[4] / 3.0 / tau]
    return np.array(q + [ms[10]])


def species_values(s):
    """Per record and species, the 11 values species_quantities() takes: shape (records, species, 11)."""
    return np.concatenate([s['species/stress_hydro'], s['species/stress_contact'], s['species/solid_fraction'][:, :, None]],
                          axis=2)


def partial_g(a, counts, references, phi_core, volumes=None):
    """g[a, b, k] = C_ab(k) / (n_b S_ab(k)), n_b = (phi_core,b / v_b) (N_b - delta_ab) / N_b (the core's
    number density of species b without the reference itself), S_ab(k) the shell volume around the
    references where a centre of b can be: R_a V_k, or between walls the sampled volumes[a, b, k];
    counts[a, b, k]."""
    ns, nr = counts.shape[0], counts.shape[2]
    width = a['radial_width'] * a['radius']
    k = np.arange(1, nr + 1)
    shell = 4.0 / 3.0 * math.pi * width ** 3 * (k ** 3 - (k - 1) ** 3)
    if volumes is None:
        volumes = references[:, None, None] * np.ones((ns, ns, 1)) * shell
    radius = np.array([a['species_radius_%d' % (j + 1)] for j in range(ns)]) * a['radius']
    count = np.array([a['species_count_%d' % (j + 1)] for j in range(ns)])
    g = np.full(counts.shape, NAN)
    for i in range(ns):
        for j in range(ns):
            density = phi_core[j] / (4.0 / 3.0 * math.pi * radius[j] ** 3) * (count[j] - (i == j)) / count[j]
            if density > 0 and np.all(volumes[i, j] > 0):
                g[i, j] = counts[i, j] / (density * volumes[i, j])
    return g


def summarise_species(a, s, block, complete, nrec):
    """The per-species summary of a mixture (mod_rheology::rheo_summarise_species): quantities
    (value, error per species), profiles phi_s(y), their block errors and n_s(y), and g_ab(r)
    with its block errors, over the complete blocks."""
    ns = int(a['species'])
    radius = np.array([a['species_radius_%d' % (j + 1)] for j in range(ns)]) * a['radius']
    values, sv = core_values(s), species_values(s)
    counts = s.get('species/pair_counts')
    nr = counts.shape[3] if counts is not None else 0
    out = {'radius': [a['species_radius_%d' % (j + 1)] for j in range(ns)],
           'count': [a['species_count_%d' % (j + 1)] for j in range(ns)],
           'quantities': {n: {'value': np.full(ns, NAN), 'error': np.full(ns, NAN)} for n in SPECIES_NAMES},
           'profiles': {}, 'pair_distribution': {'radial_width': a['radial_width'],
                                                 'r': (np.arange(nr) + 0.5) * a['radial_width']}}
    nbins = s['species/profile_solid_fraction'].shape[2]
    nan_prof = np.full((ns, nbins), NAN)
    out['profiles'] = {'solid_fraction': nan_prof, 'solid_fraction_error': nan_prof, 'number_density': nan_prof}
    out['pair_distribution'].update({'g': np.full((ns, ns, nr), NAN), 'g_error': np.full((ns, ns, nr), NAN)})
    if complete == 0:
        return out
    sel = [block == b for b in range(complete)]
    means = [values[m].mean(axis=0) for m in sel]
    smeans = [sv[m].mean(axis=0) for m in sel]
    per_block = np.array([[species_quantities(m, ms[j]) for j in range(ns)] for m, ms in zip(means, smeans)])
    mean, smean = np.mean(means, axis=0), np.mean(smeans, axis=0)
    value = np.array([species_quantities(mean, smean[j]) for j in range(ns)])
    error = per_block.std(axis=0, ddof=1) / math.sqrt(complete) if complete > 1 else np.full(value.shape, NAN)
    for k, n in enumerate(SPECIES_NAMES):
        out['quantities'][n] = {'value': value[:, k], 'error': error[:, k]}
    prof = s['species/profile_solid_fraction']
    inside = (block >= 0) & (block < complete)
    phi = prof[inside].sum(axis=0) / nrec
    phi_blocks = np.array([prof[m].mean(axis=0) for m in sel])
    out['profiles'] = {'solid_fraction': phi,
                       'solid_fraction_error': phi_blocks.std(axis=0, ddof=1) / math.sqrt(complete)
                       if complete > 1 else nan_prof,
                       'number_density': phi / (4.0 / 3.0 * math.pi * radius[:, None] ** 3)}
    if nr > 0:
        refs = s['species/references']
        vol = s.get('species/pair_volumes')     # between walls: the sampled shell volumes

        def volumes(m):
            return vol[m].sum(axis=0) if vol is not None else None
        g = partial_g(a, counts[inside].sum(axis=0), refs[inside].sum(axis=0), smean[:, 10], volumes(inside))
        g_blocks = np.array([partial_g(a, counts[m].sum(axis=0), refs[m].sum(axis=0), ms[:, 10], volumes(m))
                             for m, ms in zip(sel, smeans)])
        out['pair_distribution']['g'] = g
        if complete > 1:
            out['pair_distribution']['g_error'] = g_blocks.std(axis=0, ddof=1) / math.sqrt(complete)
    return out


def load(outdir):
    """(a, s): the settings of a run (attributes written by fdsusp, as numbers) and its series
    (the columns the statistics use); records still in series.parts/ (a running or killed run)
    included (fdsusp.series). NoRheology when the run had no &rheology."""
    names = ['step', 'time', 'core/stress_hydro', 'core/stress_contact', 'core/solid_fraction', 'core/velocity_fit',
             'core/flow_fit', 'core/shear_rate', 'pairs/references', 'pairs/shell', 'pairs/contact',
             'profiles/solid_fraction', 'profiles/momentum']
    # the crystalline order, when the run measured it (doc/RHEOLOGY.md "Order")
    order = ['structure/q6', 'structure/q6_local']
    try:
        present = series.names(outdir)
        if all(n in present for n in order):
            names += order
        # a mixture's per-species columns (doc/RHEOLOGY.md "Per species")
        names += [n for n in SPECIES_COLUMNS if n in present]
        s, attrs = series.read(outdir, names)
    except KeyError:
        raise NoRheology(f'{outdir}/series.h5 holds no core statistics: the run had no &rheology')
    return series.settings(attrs), s


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
        raise ValueError('--window: blocks and average_strain/blocks must be at least one step')
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
        q = quantities(values[m].mean(axis=0), a['shear_rate'], _fixed_rate(a))
        out['strain_start'].append(k * width)
        for n in names:
            v = q[NAMES.index(n)]
            out[n].append(float(v) if math.isfinite(v) else None)
    return out


def as_json(a, summ):
    """A recomputed summary with the keys of fdsusp's summary.json (NaN as null)."""
    def clean(x):
        if np.ndim(x) > 1:
            return [clean(v) for v in x]
        return [None if not math.isfinite(v) else float(v) for v in x]
    out = {'program': 'scripts/rheology.py', 'complete': summ['blocks_complete'] == summ['blocks'],
            'blocks': summ['blocks'], 'blocks_complete': summ['blocks_complete'],
            'discard_step': int(a['discard_step']), 'block_steps': int(a['block_steps']),
            'last_step': summ['last_step'], 'records_per_block': summ['records_per_block'], 'core': [a['core_lo'], a['core_hi']], 'shear_rate': a['shear_rate'],
            'quantities': {n: {k: (v if math.isfinite(v) else None) for k, v in q.items()}
                           for n, q in summ['quantities'].items()},
            'profiles': {k: clean(v) for k, v in summ['profiles'].items()},
            'pair_distribution': {'r_outer': a['pair_radius'], 'r_contact': a['contact_radius'],
                                  **{k: clean(v) for k, v in summ['pair_distribution'].items()}}}
    if 'species' in summ:
        sp = summ['species']
        out['species'] = {'radius': sp['radius'], 'count': sp['count'],
                          'quantities': {n: {k: clean(v) for k, v in q.items()} for n, q in sp['quantities'].items()},
                          'profiles': {k: clean(v) for k, v in sp['profiles'].items()},
                          'pair_distribution': {k: (clean(v) if np.ndim(v) else v)
                                                for k, v in sp['pair_distribution'].items()}}
    return out


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
    fixed = _fixed_rate(a)
    value = quantities(np.mean(means, axis=0), a['shear_rate'], fixed) if complete > 0 else np.full(len(NAMES), NAN)
    error = np.full(len(NAMES), NAN)
    if complete > 1:
        per_block = np.array([quantities(m, a['shear_rate'], fixed) for m in means])
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
        if a.get('species', 1) > 1:
            # a mixture: the core's number density from the mean sphere volume (doc/RHEOLOGY.md)
            ns = int(a['species'])
            count = [a['species_count_%d' % (j + 1)] for j in range(ns)]
            volume = [4.0 / 3.0 * math.pi * (a['species_radius_%d' % (j + 1)] * a['radius']) ** 3 for j in range(ns)]
            n_core = value[25] / (np.dot(count, volume) / sum(count))
        refs = s['pairs/references'][inside].sum()
        shells = [(r ** 3 - (2 * a['radius']) ** 3) / 3.0 * dtheta * 2 * math.sin(0.5 * dtheta)
                  for r in (a['pair_radius'], a['contact_radius'])]
        g = s['pairs/shell'][inside].sum(axis=0) / (refs * n_core * shells[0])
        gc = s['pairs/contact'][inside].sum(axis=0) / (refs * n_core * shells[1])
    else:
        phi = velocity = np.full(nbins, NAN)
        g = gc = np.full(nang, NAN)
    out = {'blocks': blocks, 'blocks_complete': complete, 'last_step': last_step,
           'records_per_block': [float(r) for r in records],
           'quantities': {n: {'value': v, 'error': e} for n, v, e in zip(NAMES, value, error)},
           'profiles': {'y': y, 'solid_fraction': phi, 'velocity': velocity},
           'pair_distribution': {'theta': theta, 'g': g, 'g_contact': gc}}
    if a.get('species', 1) > 1:
        out['species'] = summarise_species(a, s, block, complete, nrec)
    return out


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
    if ('species' in theirs) != ('species' in ours):
        bad.append('species: in one summary only')
    elif 'species' in ours:
        a, b = theirs['species'], ours['species']
        pairs = [(f'species {n} {part}', a['quantities'][n][part], b['quantities'][n][part])
                 for n in SPECIES_NAMES for part in ('value', 'error')]
        pairs += [(f'species profiles/{k}', a['profiles'][k], b['profiles'][k]) for k in a['profiles']]
        pairs += [(f'species pair_distribution/{k}', a['pair_distribution'][k], b['pair_distribution'][k])
                  for k in ('r', 'g', 'g_error')]
        for what, x, y in pairs:
            x = np.array([np.nan if v is None else v for v in np.ravel(np.array(x, dtype=object))], dtype=float)
            y = np.ravel(np.asarray(y, dtype=float))
            if x.shape != y.shape:
                bad.append(f'{what}: shapes {x.shape} vs {y.shape}')
                continue
            for i, (u, v) in enumerate(zip(x, y)):
                if differs(u, v):
                    bad.append(f'{what}[{i}]: {u} vs {v}')
                    break
    return bad


def summary_lines(outdir, summ):
    """The lines scripts/rheology.py prints for a summary."""
    lines = [f"{outdir}: {summ['blocks_complete']} of {summ['blocks']} blocks complete (last step {summ['last_step']})"]
    for n in NAMES:
        q = summ['quantities'][n]
        lines.append(f"  {n:16s} {q['value']:13.5e} +- {q['error']:10.3e}")
    return lines


def print_summary(outdir, summ):
    print('\n'.join(summary_lines(outdir, summ)))


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


def contact_statistics(outdir, discard_strain):
    """Means over the averaged records (strain > discard) of the contact columns of the run's
    series: contacts between spheres and with the walls, the fraction of them sliding (at the
    Coulomb limit), and the largest overlap of each record in units of h_r."""
    cols, attrs = series.read(outdir, ['time', 'contacts_pair', 'contacts_wall', 'contacts_sliding',
                                       'contact_overlap_over_roughness'])
    strain = cols['time'] * abs(float(np.ravel(attrs['shear_rate'])[0]))
    keep = strain > discard_strain
    pair, wall, sliding = (cols[k][keep] for k in ('contacts_pair', 'contacts_wall', 'contacts_sliding'))
    overlap = cols['contact_overlap_over_roughness'][keep]
    total = pair + wall
    return {'records': int(keep.sum()), 'pair_contacts': float(pair.mean()), 'wall_contacts': float(wall.mean()),
            'sliding_fraction': float(sliding.sum() / total.sum()) if total.sum() > 0 else 0.0,
            'largest_overlap_over_h_r_mean': float(overlap.mean()), 'largest_overlap_over_h_r_max': float(overlap.max())}
