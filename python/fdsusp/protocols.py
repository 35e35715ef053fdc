"""The analysis of the rheometer's protocols from a run's series (doc/RHEOLOGY.md "Protocols";
the deck's &shear, doc/INPUT.md): the stress transient after shear reversals, the moduli of an
oscillation and the stroboscopic displacement of the spheres between its cycles.

Each record holds `shear/rate` (the imposed rate gamma_dot(t_n) of the step the record's statistics
were sampled in), `shear/strain` (gamma(t_n) of that configuration) and the core stresses
`core/stress_hydro`, `core/stress_contact` (xx, yy, zz, xy, trace; particle stresses, units
eta*gamma_dot) of the configuration X^n; `particles/position` is X^{n+1}, the configuration after
the record's step, at the record's `time`. The solvent's own stress eta*gamma_dot(t_n) is added to
the hydrodynamic shear stress here. Stresses are returned in units of eta*|reference rate|
(the series attribute shear_reference_rate; the rate of the deck, or gamma_0 2 pi/T).

    from fdsusp import protocols
    r = protocols.reversal_transient('out/rev')        # strain since reversal, mean and error
    m = protocols.oscillation_moduli('out/osc')        # G', G'' (harmonics 1 and 3), per period
    d = protocols.stroboscopic_msd('out/osc')          # <|dx|^2> between cycles
    v = protocols.stress_control_rate('out/stress')     # mean rate and S/<rate> under stress control
    w = protocols.wall_shear_stress('out/dns')          # the DNS's mean wall shear stress and its parts
"""
import math

import numpy as np

from . import series

STRESS_COLUMNS = ['shear/rate', 'shear/strain', 'time', 'core/stress_hydro', 'core/stress_contact']


class NoProtocol(ValueError):
    """The run's series holds no protocol (a steady rate, or no shear/rate column)."""


def settings(outdir):
    """The protocol of a run from its series attributes: {'protocol': 'steady'|'reversal'|'oscillatory'|'steps',
    'reference_rate', 'reversal_strain', 'strain_amplitude', 'period', 'dt', 'control': 'rate'|'stress',
    'stress'} (a steady protocol records them under stress control only)."""
    _, attributes = series.read(outdir, ['shear/rate'])
    a = series.settings(attributes)
    if 'shear_protocol' not in a:
        raise NoProtocol(f'{outdir}: the series records no varying protocol (&shear protocol steady?)')
    kind = {1: 'steady', 2: 'reversal', 3: 'oscillatory', 4: 'steps'}[int(a['shear_protocol'])]
    control = {1: 'rate', 2: 'stress'}[int(a.get('shear_control', 1))]
    return {'protocol': kind, 'reference_rate': a['shear_reference_rate'], 'reversal_strain': a['shear_reversal_strain'],
            'strain_amplitude': a['shear_strain_amplitude'], 'period': a['shear_period'], 'dt': a['shear_dt'],
            'control': control, 'stress': a.get('shear_stress', 0.0)}


def stresses(columns):
    """Per record: shear stresses (total, hydrodynamic with the solvent, contact) and N1, N2 (total,
    hydrodynamic, contact), in the units of the series (eta*gamma_dot)."""
    rate = columns['shear/rate']
    h, c = columns['core/stress_hydro'], columns['core/stress_contact']
    out = {'shear_h': rate + h[:, 3], 'shear_c': c[:, 3]}
    out['shear'] = out['shear_h'] + out['shear_c']
    for name, s in (('h', h), ('c', c), ('', h + c)):
        suffix = '_' + name if name else ''
        out['N1' + suffix] = s[:, 0] - s[:, 1]
        out['N2' + suffix] = s[:, 1] - s[:, 2]
    return out


def reversal_transient(outdir, skip_reversals=0):
    """The stress against the strain since the last reversal, averaged over the reversals.

    A reversal starts at each record whose rate has the opposite sign of the record before. The
    strain since it is measured from the turning point gamma_r, the strain of the configuration at
    which the rate changed sign, whether or not a record holds it (series_every > 1): with |rate|
    constant the records either side of the turn, at configurations n1 < n2, give
    gamma_r = (gamma(n1) + gamma(n2) - rate(n2) dt (n2 - n1))/2; with series_every 1 gamma_r is the
    strain of the reversal record itself. The strain since it, |gamma(t_n) - gamma_r|, is binned on
    the grid of the records (series_every steps) starting at the first reversal's offset (the
    records of every reversal share it when reversal_strain is a whole number of series_every
    steps). The shear stresses are signed with the current direction (positive when they resist
    the flow); N1, N2 as they are. Each is averaged over the reversals after the first
    skip_reversals, with its standard error (standard deviation over the reversals, ddof 1, /
    sqrt(count); NaN from one reversal). Returns {'strain': (k,), 'count': (k,), 'reversal_steps':
    steps of the first records after each reversal, 'turning_strain': gamma_r of each, name:
    {'mean': (k,), 'error': (k,)}} with the names of stresses(), in eta*|reference rate|."""
    p = settings(outdir)
    columns, _ = series.read(outdir, STRESS_COLUMNS + ['step'])
    return reversal_transient_columns(columns, p, skip_reversals)


def reversal_transient_columns(columns, p, skip_reversals=0):
    """reversal_transient from the series columns (STRESS_COLUMNS and 'step') and the protocol
    settings p (settings(): 'reference_rate', 'dt')."""
    rate, strain, step = columns['shear/rate'], columns['shear/strain'], columns['step']
    sign = np.sign(rate)
    starts = np.flatnonzero(sign[1:] != sign[:-1]) + 1
    starts = starts[skip_reversals:]
    if len(starts) == 0:
        raise NoProtocol('no reversal in the series')
    ends = list(starts[1:]) + [len(rate)]
    s = stresses(columns)
    unit = abs(p['reference_rate'])
    dt = p['dt']
    step_strain = unit * dt * max(1, int(np.median(np.diff(step))))
    turns = [(strain[a - 1] + strain[a] - rate[a] * dt * (step[a] - step[a - 1])) / 2 for a in starts]
    offset = None
    segments = []
    for a, b, turn in zip(starts, ends, turns):
        since = np.abs(strain[a:b] - turn)
        if offset is None:
            offset = since[0] - step_strain * np.floor(since[0] / step_strain + 1e-9)
        bins = np.rint((since - offset) / step_strain).astype(int)
        segments.append((bins, a, b))
    nbins = max(seg[0].max() for seg in segments) + 1
    result = {'strain': offset + np.arange(nbins) * step_strain, 'reversal_steps': step[starts],
              'turning_strain': np.array(turns)}
    counts = np.zeros(nbins, int)
    for bins, _, _ in segments:
        counts[bins] += 1
    result['count'] = counts
    for name, values in s.items():
        signed = values * sign if name.startswith('shear') else values
        table = np.full((len(segments), nbins), np.nan)
        for k, (bins, a, b) in enumerate(segments):
            table[k, bins] = signed[a:b] / unit
        with np.errstate(invalid='ignore', divide='ignore'):
            mean = np.nanmean(table, axis=0)
            n = np.sum(np.isfinite(table), axis=0)
            sd = np.nanstd(table, axis=0, ddof=1) if len(segments) > 1 else np.full(nbins, np.nan)
            error = np.where(n > 1, sd / np.sqrt(np.maximum(n, 1)), np.nan)
        result[name] = {'mean': mean, 'error': error}
    return result


def _phase_times(columns, dt):
    """t_n of each record: the time of the configuration its statistics were sampled at."""
    return columns['time'] - dt


def harmonic_fit(t, y, omega, harmonics=(1, 3)):
    """Least squares of y(t) = c + sum_h a_h sin(h omega t) + b_h cos(h omega t): (c, {h: (a_h, b_h)})."""
    cols = [np.ones_like(t)]
    for h in harmonics:
        cols += [np.sin(h * omega * t), np.cos(h * omega * t)]
    coef, *_ = np.linalg.lstsq(np.array(cols).T, y, rcond=None)
    return coef[0], {h: (coef[1 + 2 * k], coef[2 + 2 * k]) for k, h in enumerate(harmonics)}


def oscillation_moduli(outdir, harmonics=(1, 3), skip_periods=0, part='shear'):
    """The moduli of an oscillation gamma(t) = gamma_0 sin(omega t): over each whole period after
    the first skip_periods, the least squares of the shear stress (part: 'shear' total, 'shear_h'
    hydrodynamic with the solvent, 'shear_c' contact) against sin(h omega t), cos(h omega t) for h
    in harmonics; G'_h = a_h / gamma_0 (in phase with the strain), G''_h = b_h / gamma_0 (with the
    rate). Returns {'omega', 'gamma_0', 'periods', h: {"G'": (mean, error), "G''": (mean, error),
    'per_period': [(G', G''), ...]}}, moduli in eta*gamma_dot (stress over strain; G''/omega is a
    viscosity in eta); error: standard deviation over the periods (ddof 1) / sqrt(periods)."""
    p = settings(outdir)
    if p['protocol'] != 'oscillatory':
        raise NoProtocol(f'{outdir}: protocol {p["protocol"]}, not oscillatory')
    columns, _ = series.read(outdir, STRESS_COLUMNS)
    omega = 2 * math.pi / p['period']
    gamma_0 = p['strain_amplitude']
    t = _phase_times(columns, p['dt'])
    y = stresses(columns)[part]
    cycle = np.floor(t / p['period'] + 1e-9).astype(int)
    last = int(np.floor((t[-1] + p['dt']) / p['period'] + 1e-9))   # periods complete by the last record
    periods = [k for k in range(skip_periods, last) if np.count_nonzero(cycle == k) >= 4]
    if not periods:
        raise NoProtocol(f'{outdir}: no whole period after {skip_periods}')
    result = {'omega': omega, 'gamma_0': gamma_0, 'periods': periods}
    per = {h: [] for h in harmonics}
    for k in periods:
        sel = cycle == k
        _, coef = harmonic_fit(t[sel], y[sel], omega, harmonics)
        for h in harmonics:
            per[h].append((coef[h][0] / gamma_0, coef[h][1] / gamma_0))
    for h in harmonics:
        v = np.array(per[h])
        n = len(v)
        err = v.std(axis=0, ddof=1) / math.sqrt(n) if n > 1 else np.full(2, np.nan)
        result[h] = {"G'": (v[:, 0].mean(), err[0]), "G''": (v[:, 1].mean(), err[1]), 'per_period': per[h]}
    return result


def unwrapped_displacements(x0, x1, box, offset=0.0, lees_edwards=True):
    """x1 - x0 for each sphere (N x 3), across the periodic boundaries: a jump of more than Ly/2 in
    y is a crossing of the sliding boundary (Lees-Edwards: x shifted by the offset delta of x1's
    configuration; between walls y is taken as it is), then the minimum image in x and z."""
    d = np.array(x1, float) - np.array(x0, float)
    if lees_edwards:
        s = np.rint(d[:, 1] / box[1])
        d[:, 1] -= s * box[1]
        d[:, 0] -= s * offset
    for k in (0, 2):
        d[:, k] -= box[k] * np.rint(d[:, k] / box[k])
    return d


def stroboscopic_msd(outdir, box, lees_edwards=True, threshold=None):
    """The spheres seen at the same phase of every cycle (the records at t = k T, after whole
    periods: strain 0): the mean square displacement <|x_{k+1} - x_k|^2> between consecutive
    cycles (unwrapped_displacements) and, with threshold [a], the fraction of spheres that moved
    farther. Needs series_every to divide the steps per period. Returns {'cycles': (m,),
    'msd': (m-1,), 'moved': (m-1,) or None}."""
    p = settings(outdir)
    columns, _ = series.read(outdir, ['time', 'particles/position'] + (['lees_edwards_offset'] if lees_edwards else []))
    steps_per_period = p['period'] / p['dt']
    k = columns['time'] / p['period']
    at_phase = np.flatnonzero(np.abs(k - np.rint(k)) * steps_per_period < 1e-6)
    if len(at_phase) < 2:
        raise NoProtocol(f'{outdir}: fewer than two records at whole periods')
    x = columns['particles/position']
    msd, moved = [], []
    for a, b in zip(at_phase[:-1], at_phase[1:]):
        offset = columns['lees_edwards_offset'][b] if lees_edwards else 0.0
        d = unwrapped_displacements(x[a], x[b], box, offset, lees_edwards)
        r2 = np.sum(d * d, axis=1)
        msd.append(r2.mean())
        if threshold is not None:
            moved.append(float(np.mean(np.sqrt(r2) > threshold)))
    return {'cycles': np.rint(k[at_phase]).astype(int), 'msd': np.array(msd),
            'moved': np.array(moved) if threshold is not None else None}


def stress_control_rate(outdir):
    """The mean rate of a stress-controlled run (&shear control = 'stress', doc/RHEOLOGY.md "Stress
    control") over its &rheology window, as the summary takes its blocks (the records on the
    series_every grid after discard_step, `blocks` blocks of block_steps steps, the complete ones):
    {'stress': S, 'rate': mean of the block means of shear/rate, 'rate_error': their standard
    deviation (ddof 1) / sqrt(blocks), 'viscosity': S / rate, 'viscosity_error': S rate_error /
    rate^2, 'blocks': the complete blocks}, in units of gamma_dot_ref and eta. Stress steps are not
    averaged here (NoProtocol)."""
    columns, attributes = series.read(outdir, ['step', 'shear/rate'])
    a = series.settings(attributes)
    if int(a.get('shear_control', 1)) != 2 or int(a.get('shear_protocol', 1)) != 1:
        raise NoProtocol(f'{outdir}: not a steady stress-controlled run (&shear control = \'stress\')')
    step = np.rint(columns['step']).astype(np.int64)
    blocks, discard, block_steps = int(a['blocks']), int(a['discard_step']), int(a['block_steps'])
    every = int(a['series_every'])
    block = np.where((step > discard) & (step % every == 0), (step - discard - 1) // block_steps, -1)
    block[block >= blocks] = -1
    last_step = int(step.max())
    complete = 0
    for b in range(1, blocks + 1):
        if discard + b * block_steps <= last_step and np.any(block == b - 1):
            complete = b
    if complete < 2:
        raise ValueError(f'{outdir}: fewer than 2 complete blocks of the &rheology window')
    means = np.array([columns['shear/rate'][block == b].mean() for b in range(complete)])
    rate = means.mean()
    error = means.std(ddof=1) / math.sqrt(complete)
    stress = a['shear_stress']
    return {'stress': stress, 'rate': rate, 'rate_error': error, 'viscosity': stress / rate,
            'viscosity_error': stress * error / rate ** 2, 'blocks': complete}


def wall_shear_stress(outdir):
    """The mean wall shear stress of every record of a DNS between walls (doc/METHOD.md §7.4, the
    stress that stress control sets): the force on the walls per area, sigma_w = fluid +
    lubrication + contact, with fluid = (tau_wall_bottom + tau_wall_top)/2 (the grid's viscous
    stress) and the walls' force on the spheres through the wall lubrication links and the wall
    contacts, (F_top,x - F_bottom,x)/(2 Lx Lz) (columns wall_force_lubrication, wall_force_contact:
    record x wall (lower, upper) x component; absent: zero). {'step', 'sigma', 'fluid',
    'lubrication', 'contact'}, in eta*gamma_dot_ref."""
    columns, attributes = series.read(outdir)
    if 'tau_wall_bottom' not in columns:
        raise KeyError(f'{outdir}: no wall stresses (not a DNS between walls)')
    area = float(np.ravel(attributes['box_x'])[0]) * float(np.ravel(attributes['box_z'])[0])
    fluid = 0.5 * (columns['tau_wall_bottom'] + columns['tau_wall_top'])
    share = {}
    for part in ('lubrication', 'contact'):
        f = columns.get('wall_force_' + part)
        share[part] = np.zeros_like(fluid) if f is None else (f[:, 1, 0] - f[:, 0, 0]) / (2.0 * area)
    return {'step': columns['step'], 'sigma': fluid + share['lubrication'] + share['contact'], 'fluid': fluid,
            'lubrication': share['lubrication'], 'contact': share['contact']}
