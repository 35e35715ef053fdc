"""The paper's pair test in the DNS against bin/pairtraj (Gallier et al. 2014 JFM §3): the cases,
their decks, the runs, the branch of every case from a shared approach (the trunk), and the
comparison of the DNS pair with pairtraj's trajectory and the exact free-pair mobility. The
command line is scripts/pair_dns.py (its --help says what is run and compared, doc/VALIDATION.md
§4.4); tests/physics/test_pair_dns.py runs a shortened version through these functions.
"""
import math
import os
import re
import shutil
import subprocess

import numpy as np

from . import deck as fdeck, series
from .resistance import shear_functions
from .run import ENV, MPIEXEC, checkout, copy_program, program, run_all

# the checkout: the pairtraj decks of the cases (input/pair_*.nml) are the templates
ROOT = checkout()
S_INF = 20.0 / 3.0 * math.pi
# case: (pairtraj deck under input/ used as the template, eps_r, mu_d)
CASES = {'eps0': ('pair_eps0', 0.0, 0.0),
         'eps1e-3': ('pair_eps1e-3', 1e-3, 0.0),
         'eps1e-3_mu03': ('pair_eps1e-3_mu03', 1e-3, 0.3),
         'eps1e-2': ('pair_eps1e-2', 1e-2, 0.0),
         'eps1e-2_mu03': ('pair_eps1e-2_mu03', 1e-2, 0.3)}
Y0 = 0.5          # initial offset across the shear, a (the paper's)
STARTUP = 0.25    # strain over which the DNS stresslets build up from zero (lambda starts at 0)
BRANCH_GAP = 0.1  # the trunk of --branch ends before pairtraj's gap falls below this: 10 h_r of the roughest case
TRUNK_CASE = 'eps1e-2'   # the trunk's deck: contacts on (its series has the contact columns), touches first
EXTEND = 0.1      # a DNS that has not crossed by its last step goes on by this fraction of the transit

# Smooth spheres (eps_r = 0) get no &contact group: lubrication alone keeps them apart, as in
# pairtraj, whose smooth pair never touches (its closest gap from y = 0.5a is 8.7e-5 a).
def dns_deck(case, box, cells, reynolds, theta, dt, steps, hours, x1, y1, x2, y2, c, contact, boundary='walls'):
    """The DNS deck of a case (fdsusp.deck; numbers to 12 digits, as this study always wrote them);
    contact: the &contact settings, None for smooth spheres; boundary: the deck's y_boundary."""
    every = record_every(dt)
    groups = [('domain', {'box': (box, box, box), 'cells_per_radius': cells, 'y_boundary': boundary, 'shear_rate': 1}),
              ('fluid', {'reynolds': reynolds, 'viscous_theta': theta, 'initial_flow': 'shear'}),
              ('time', {'dt': dt, 'steps': steps}),
              ('output', {'directory': 'out', 'progress_every': max(1, steps // 20), 'series_every': every,
                          'checkpoint_every': max(1, steps // 10)}),
              ('run', {'title': 'pair test %s' % case, 'max_wall_hours': hours}),
              ('particles', {'number': 2, 'position(:,1)': (x1, y1, c), 'position(:,2)': (x2, y2, c)}),
              ('lubrication', {'model': 'full'})]
    if contact is not None:
        groups.append(('contact', contact))
    return fdeck.text(groups, comment='pair test in the DNS, written by scripts/pair_dns.py (case %s)' % case,
                      float_format='%.12g')


def override(text, **values):
    """A namelist deck's text with the given variables' values replaced (each must occur once)."""
    for var, value in values.items():
        text, n = re.subn(r'(?im)^(\s*%s\s*=\s*)[^\n!]*' % re.escape(var), r'\g<1>%s' % value, text)
        if n != 1:
            raise SystemExit('pair_dns.py: variable %s not found once in the pairtraj deck' % var)
    return text


def pairtraj(case, d, start, eps_bar):
    """Run bin/pairtraj for the case from r = (start, Y0, 0) to x = -start; return its CSV rows."""
    template, _, _ = CASES[case]
    with open(os.path.join(ROOT, 'input', template + '.nml')) as f:
        text = f.read()
    deck = os.path.join(d, 'pairtraj.nml')
    with open(deck, 'w') as f:
        f.write(override(text, start='%r, %r, 0.0' % (start, Y0), x_end=repr(-start),
                         eps_bar=repr(eps_bar), csv_file="'pairtraj.csv'", dt_out='0.01'))
    subprocess.run([program('pairtraj'), 'pairtraj.nml'], cwd=d, check=True,
                   stdout=subprocess.DEVNULL)
    return read_pairtraj(d)


def read_pairtraj(d):
    return np.genfromtxt(os.path.join(d, 'pairtraj.csv'), delimiter=',', names=True)


def record_every(dt):
    return max(1, int(round(0.01 / dt)))                      # a record every 0.01 strain


def prepare(case, d, box, cells, dt, start, eps_bar=0.05, reynolds=0.01, theta=0.5, hours=0.0, steps_factor=1.05,
            steps=None, branched=False, lees_edwards=None):
    """Write the case's decks, run pairtraj; return the DNS command (continuing from a checkpoint
    when there is one). The DNS runs for steps_factor times pairtraj's transit time, or to step
    `steps` when given. branched: the case was branched from the trunk (branch()), so its
    checkpoint may be the trunk's, of other contact physics: fdsusp continues it with -branch,
    which takes this deck's contact model (doc/INPUT.md "Restart"); with the case's own
    checkpoint -branch checks what -restart does. lees_edwards: a Lees-Edwards box instead of the
    Couette cell, with the pair centred on the sliding boundary y = 0 ('boundary': sphere 1 below
    it, in the top of the box; doc/METHOD.md §3.9), so that it crosses the boundary throughout, or
    centred in the box ('centre')."""
    os.makedirs(d, exist_ok=True)
    ref = pairtraj(case, d, start, eps_bar)
    _, eps_r, mu_d = CASES[case]
    if steps is None:
        steps = int(math.ceil(steps_factor * ref['t'][-1] / dt))
        if os.path.exists(os.path.join(d, 'deck.nml')):
            steps = max(steps, deck_steps(d))                # a continued case keeps its extension
    c = box / 2.0
    # smooth spheres (eps_r = 0) get no &contact group (above)
    contact = None if eps_r == 0 else {'roughness': eps_r, 'eps_bar': eps_bar, 'friction': mu_d}
    y1, y2 = (box - Y0 / 2, Y0 / 2) if lees_edwards == 'boundary' else (c - Y0 / 2, c + Y0 / 2)
    fdeck.write(os.path.join(d, 'deck.nml'),
                dns_deck(case, box, cells, reynolds, theta, dt, steps, hours, x1=c - start / 2, y1=y1,
                         x2=c + start / 2, y2=y2, c=c, contact=contact,
                         boundary='lees-edwards' if lees_edwards else 'walls'))
    binary = os.path.join(d, 'fdsusp')          # a copy: a rebuild cannot change a study half-way
    if not os.path.exists(binary):
        copy_program(binary)
    command = [binary, 'deck.nml']
    if os.path.exists(os.path.join(d, 'out', 'checkpoint.h5')):
        command += ['-branch' if branched else '-restart', 'out/checkpoint.h5']
    return command


def start_dns(d, command, ranks):
    if ranks > 1:
        command = MPIEXEC + ['-n', str(ranks)] + command
    log = open(os.path.join(d, 'log'), 'a')
    log.write('\n# %s\n' % ' '.join(command))
    log.flush()
    return subprocess.Popen(command, cwd=d, env=ENV, stdout=log, stderr=subprocess.STDOUT)


def series_steps(d):
    """The steps of the records a case's series holds, series.parts/ included (empty before its
    first flush)."""
    out = os.path.join(d, 'out')
    if not series.files(out):
        return np.zeros(0, dtype=int)
    return series.read(out, ['step'])[0]['step']


def deck_steps(d):
    with open(os.path.join(d, 'deck.nml')) as f:
        return int(re.search(r'steps = (\d+)', f.read()).group(1))


def continuation(d, box, start, dt):
    """For a case whose DNS ran to its deck's last step: None when its pair has crossed x = -start,
    else the step to continue it to (EXTEND of pairtraj's transit more, as scripts/pair_dns.py
    does). A restart repeats the arithmetic of one longer run exactly (test_restart), so the
    records of a continued case are those of a run given the longer deck from the start."""
    if upto(load_dns(d, box), -start)[1] is not None:
        return None
    transit = float(read_pairtraj(d)['t'][-1])
    return deck_steps(d) + int(math.ceil(EXTEND * transit / dt))


def run_to_crossing(cases, dirs, prepare_case, box, start, dt, jobs=2, rounds=2):
    """Run each case's DNS on one rank, at most jobs at a time (prepare_case(c, steps=None) writes
    its decks and returns its command, to `steps` when given), then continue, at most `rounds`
    times, the cases that ran whole and whose pair has not crossed x = -start (continuation()).
    Returns {case: (exit status, CPU seconds summed over its runs)}."""
    commands = {c: prepare_case(c) for c in cases}
    status = run_all(cases, lambda c: start_dns(dirs[c], commands[c], 1), jobs)
    for _ in range(rounds):
        more = {c: continuation(dirs[c], box, start, dt) for c in cases if status[c][0] == 0}
        more = {c: steps for c, steps in more.items() if steps is not None}
        if not more:
            break
        for c, steps in more.items():
            print('%s: not across x = %g by step %d; continued to step %d' % (c, -start, deck_steps(dirs[c]), steps))
            commands[c] = prepare_case(c, steps=steps)
        for c, (code, cpu) in run_all(list(more), lambda c: start_dns(dirs[c], commands[c], 1), jobs).items():
            status[c] = (code, status[c][1] + cpu)
    return status


def trunk_steps(refs, dt):
    """The trunk's last step: a record step before pairtraj's gap first falls below BRANCH_GAP in
    any of the cases (refs: their pairtraj rows)."""
    t_branch = min(float(ref['t'][np.argmax(ref['gap'] < BRANCH_GAP)]) for ref in refs)
    every = record_every(dt)
    return int(t_branch / dt) // every * every


def check_trunk(trunk, box):
    """A trunk may serve as the shared approach only if no contact force acted in it and its pair
    stayed well clear of every roughness (the cases differ in nothing else before they touch)."""
    dns = load_dns(trunk, box)
    touched = np.abs(series.read(os.path.join(trunk, 'out'), ['particles/force_contact'])[0]['particles/force_contact']).max()
    if touched > 0 or dns['gap'].min() < BRANCH_GAP / 2:
        raise SystemExit('pair_dns.py: the trunk %s cannot be shared: largest contact force %.3g, closest gap %.4f '
                         '(needs none and >= %g); run without --branch' % (trunk, touched, dns['gap'].min(),
                                                                             BRANCH_GAP / 2))


def branch(trunk, d, case):
    """Start case d from the trunk's output: its checkpoint and its series up to the checkpoint's
    step, without the contact columns when the case has no contacts (its restart extends only the
    columns it writes, and sets aside a series.h5 that lacks one). The series is read as fdsusp
    leaves it, series.h5 and series.parts/ (a trunk stopped by --hours or a kill has records in
    parts), and written whole by fdsusp.series.consolidate, so the copy holds no parts whose
    columns or steps disagree with its series.h5 (doc/DESIGN.md "series.h5: immutable parts,
    atomic consolidation")."""
    import h5py
    out = os.path.join(d, 'out')
    shutil.copytree(os.path.join(trunk, 'out'), out)
    with h5py.File(os.path.join(out, 'checkpoint.h5'), 'r') as f:
        step = int(np.ravel(f.attrs['step'])[0])
    drop = [n for n in series.names(out) if 'contact' in n] if CASES[case][1] == 0 else []
    series.consolidate(out, drop=drop, last_step=step)


def load_dns(d, box):
    """The DNS pair: time, relative position r = x2 - x1 (minimum image in x and z; in a
    Lees-Edwards box first the image in y nearest, shifted in x by the offset of its record), theta,
    and N1*, N2* of one sphere (the mean of the two, equal by symmetry), with their contact parts."""
    out = os.path.join(d, 'out')
    names = series.names(out)
    contact = 'particles/stresslet_contact' in names
    sliding = 'lees_edwards_offset' in names
    f = series.read(out, ['time', 'particles/position', 'particles/stresslet_hydro']
                    + (['particles/stresslet_contact'] if contact else [])
                    + (['lees_edwards_offset'] if sliding else []))[0]
    t = f['time']
    x = f['particles/position']
    s = f['particles/stresslet_hydro']
    sc = f['particles/stresslet_contact'] if contact else np.zeros_like(s)
    r = x[:, 1] - x[:, 0]
    if sliding:
        images = -np.round(r[:, 1] / box)
        r[:, 1] += images * box
        r[:, 0] += images * f['lees_edwards_offset']
    for k in (0, 2):
        r[:, k] -= box * np.round(r[:, k] / box)

    def normal_stresses(stresslet):
        m = stresslet.mean(axis=1)
        return 2 * (m[:, 0, 0] - m[:, 1, 1]) / S_INF, 2 * (m[:, 1, 1] - m[:, 2, 2]) / S_INF
    n1, n2 = normal_stresses(s + sc)
    n1c, n2c = normal_stresses(sc)
    return dict(t=t, x=r[:, 0], y=r[:, 1], z=r[:, 2], theta=np.arctan2(r[:, 1], r[:, 0]),
                gap=np.linalg.norm(r, axis=1) - 2, N1star=n1, N2star=n2, N1star_contact=n1c,
                N2star_contact=n2c)


def load_case(d, box, start):
    """A finished case: (DNS records, pairtraj rows, their comparison after the start-up)."""
    dns, ref = load_dns(d, box), read_pairtraj(d)
    return dns, ref, compare(dns, ref, start, skip_time=STARTUP)


def upto(d, x_end):
    """The records of d before x first reaches x_end, and the y where it does (linear
    interpolation between the records around the crossing; None when it never does)."""
    above = np.nonzero(d['x'] >= x_end)[0]
    if len(above) == 0 or above[0] == 0:
        return d, None
    k = above[0]
    w = (x_end - d['x'][k - 1]) / (d['x'][k] - d['x'][k - 1])
    return {q: v[:k] for q, v in d.items()}, d['y'][k - 1] + w * (d['y'][k] - d['y'][k - 1])


def compare(dns, ref, start, skip_time=0.0):
    """Deviations of the DNS from pairtraj over the transit x in [start, -start]; the normal
    stresses from time skip_time on (the stresslets of the DNS build up from zero at the start)."""
    part, y_end = upto(dns, -start)
    out = {'y_end_pairtraj': float(ref['y'][-1]), 'y_end_dns': y_end,
           'gap_min_dns': float(part['gap'].min()), 'gap_min_pairtraj': float(ref['gap'].min()),
           'time_dns': None if y_end is None else float(part['t'][-1]), 'time_pairtraj': float(ref['t'][-1])}
    if y_end is None:
        return out
    out['y_end_error'] = (y_end - ref['y'][-1]) / ref['y'][-1]
    out['y_max_deviation'] = float(np.abs(part['y'] - np.interp(part['x'], ref['x'], ref['y'])).max())
    late = part['t'] >= skip_time
    order = np.argsort(ref['theta'])          # theta decreases along the transit; np.interp needs it increasing
    for q in ('N1star', 'N2star', 'N1star_contact', 'N2star_contact'):
        at_dns = np.interp(part['theta'][late], ref['theta'][order], ref[q][order])
        out[q + '_abs_deviation'] = float(np.abs(part[q][late] - at_dns).max())
        out[q + '_extremes_dns'] = [float(part[q].min()), float(part[q].max())]
        out[q + '_extremes_pairtraj'] = [float(ref[q].min()), float(ref[q].max())]
    # the contact: the angles where it opens and closes (the contact parts jump there, so they are
    # compared by window and peak rather than pointwise at equal theta)
    touching = np.nonzero((part['N1star_contact'] != 0) | (part['N2star_contact'] != 0))[0]
    touching_ref = np.nonzero(ref['contact'] > 0)[0]
    if len(touching) and len(touching_ref):
        out['contact_theta_dns'] = [float(part['theta'][touching[0]]), float(part['theta'][touching[-1]])]
        out['contact_theta_pairtraj'] = [float(ref['theta'][touching_ref[0]]), float(ref['theta'][touching_ref[-1]])]
    return out


MOBILITY_GAPS = (0.02, 0.05, 0.1, 0.3)


def mobility(d, box):
    """The DNS pair's relative velocity against the exact one of a free pair at the same r, record
    by record while no contact force acts: dr/dt = Om x r + E.r - [A dd + B (I - dd)].E.r (simple
    shear of rate 1, Batchelor & Green functions from bin/fdsusp-resistance). The radial part is
    (1 - A) r d.E.d, small near contact and sensitive to the resistance ratio XG/XA (1 - A is 2.7
    times as sensitive at gap 0.1, 25 times at 0.01), so it shows where the trajectory goes wrong:
    in the approach (d.E.d < 0) or the separation (d.E.d > 0). Returns, per phase and gap of
    MOBILITY_GAPS, the relative errors (radial, tangential) at the record nearest that gap."""
    out = os.path.join(d, 'out')
    touching = 'particles/force_contact' in series.names(out)
    f = series.read(out, ['step', 'time', 'particles/position', 'particles/velocity']
                    + (['particles/force_contact'] if touching else []))[0]
    x = f['particles/position']
    v = f['particles/velocity']
    contact = np.abs(f['particles/force_contact']).sum(axis=(1, 2)) if touching else np.zeros(len(x))
    dt = (f['time'][1] - f['time'][0]) / (f['step'][1] - f['step'][0])
    dv = v[:, 1] - v[:, 0]
    # a record holds X^{n+1} and the velocity of X^n: step back, or the pair's rotation (omega dt)
    # turns v_t omega dt of tangential velocity into a spurious radial one (2.3e-3 at dt 2.5e-3)
    r = x[:, 1] - x[:, 0] - dt * dv
    for k in (0, 2):
        r[:, k] -= box * np.round(r[:, k] / box)
    dist = np.linalg.norm(r, axis=1)
    keep = (contact == 0) & (dist < 4.0)
    r, dist, dv = r[keep], dist[keep], dv[keep]
    if len(r) == 0:
        return {}                   # not near yet (a run stopped early)
    n = r / dist[:, None]
    er = np.stack([r[:, 1] / 2, r[:, 0] / 2, np.zeros(len(r))], axis=1)       # E.r
    fn = shear_functions(np.maximum(dist - 2, 1e-4))
    radial_e = np.einsum('ij,ij->i', n, er)
    tangential_e = er - radial_e[:, None] * n
    t = tangential_e / np.linalg.norm(tangential_e, axis=1)[:, None]
    rot = np.stack([r[:, 1] / 2, -r[:, 0] / 2, np.zeros(len(r))], axis=1)    # Om x r, Om = -e_z/2
    exact = rot + (1 - fn[:, 0])[:, None] * radial_e[:, None] * n + (1 - fn[:, 1])[:, None] * tangential_e
    rad = np.einsum('ij,ij->i', dv, n) / np.einsum('ij,ij->i', exact, n) - 1
    tan = np.einsum('ij,ij->i', dv, t) / np.einsum('ij,ij->i', exact, t) - 1
    out = {}
    for phase, sel in (('approach', radial_e < 0), ('separation', radial_e > 0)):
        records = np.nonzero(sel)[0]
        if len(records) == 0:
            continue
        for g in MOBILITY_GAPS:
            k = records[np.argmin(np.abs(dist[records] - 2 - g))]
            if abs(dist[k] - 2 - g) < 0.2 * g:
                out[phase, g] = (rad[k], tan[k])
    return out


def mobility_table(results):
    head = ' | '.join('%s %g' % (p[:3], g) for p in ('approach', 'separation') for g in MOBILITY_GAPS)
    rows = ['| case | %s |' % head, '|' + '---|' * (1 + 2 * len(MOBILITY_GAPS))]
    for case, m in results.items():
        cells = ['%+.1f / %+.1f' % tuple(100 * e for e in m[p, g]) if (p, g) in m else ''
                 for p in ('approach', 'separation') for g in MOBILITY_GAPS]
        rows.append('| %s | %s |' % (case, ' | '.join(cells)))
    return 'relative velocity against the free-pair mobility (radial / tangential error, %)\n' + '\n'.join(rows)


def table(comparisons):
    rows = ['| case | y_end DNS | y_end pairtraj | error | max \\|dy\\| (a) | max \\|dN1*\\| | max \\|dN2*\\| | '
            'min gap DNS / pairtraj | transit time DNS / pairtraj |', '|' + '---|' * 9]
    for case, c in comparisons.items():
        if c['y_end_dns'] is None:
            rows.append('| %s | (not across yet) | %.4f | | | | | | |' % (case, c['y_end_pairtraj']))
            continue
        rows.append('| %s | %.4f | %.4f | %+.2f %% | %.4f | %.3f | %.3f | %.2e / %.2e | %.2f / %.2f |' % (
            case, c['y_end_dns'], c['y_end_pairtraj'], 100 * c['y_end_error'], c['y_max_deviation'],
            c['N1star_abs_deviation'], c['N2star_abs_deviation'], c['gap_min_dns'], c['gap_min_pairtraj'],
            c['time_dns'], c['time_pairtraj']))
    return '\n'.join(rows)
