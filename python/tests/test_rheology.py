"""fdsusp.rheology on a synthetic series whose block means are known."""
import json
import math
import os

import numpy as np
import pytest

from conftest import write_series
from fdsusp import rheology

NB, NANG = 4, 8
ATTRS = dict(shear_rate=1.0, dt=0.01, series_every=2, blocks=5, discard_step=10, block_steps=10,
             box_y=10.0, radius=1.0, pair_radius=2.5, contact_radius=2.05, core_lo=2.0, core_hi=8.0)


def synthetic(outdir, last_step=60, attrs=ATTRS, order=False):
    """Records at every step 1..last_step: on the grid (even steps) after discard_step, the shear
    stress of block b is 1 + b (hydrodynamic) and 0.5 (contact), the shear rate 1; records before
    the discard and off the grid carry values that must not count. order: with the order columns
    (structure/q6, structure/q6_local) of a run that measured them."""
    step = np.arange(1, last_step + 1)
    n = len(step)
    block = (step - 10 - 1) // 10
    counted = (step > 10) & (step % 2 == 0)
    sh = np.zeros((n, 5))
    sc = np.zeros((n, 5))
    sh[:, 3] = np.where(counted, 1.0 + block, 1e3)
    sc[:, 3] = np.where(counted, 0.5, -1e3)
    sc[:, 1] = -2.0                      # contact pressure along y: p = 2
    fit = np.tile([3.0, 3.0, 3.0, 5.0, 5.0], (n, 1))   # points (0,0), (1,1), (2,2): slope 1
    cols = {'step': step, 'time': step * attrs['dt'], 'core/stress_hydro': sh, 'core/stress_contact': sc,
            'core/solid_fraction': np.full(n, 0.4), 'core/velocity_fit': fit, 'core/flow_fit': fit,
            'core/shear_rate': np.ones(n), 'pairs/references': np.full(n, 10.0),
            'pairs/shell': np.ones((n, NANG)), 'pairs/contact': np.ones((n, NANG)),
            'profiles/solid_fraction': np.full((n, NB), 0.4), 'profiles/momentum': np.full((n, NB), 0.2)}
    if order:
        cols['structure/q6'] = np.linspace(0.05, 0.5, n)
        cols['structure/q6_local'] = np.linspace(0.4, 0.55, n)
    write_series(os.path.join(outdir, 'series.h5'), cols, attrs)
    return outdir


def test_block_means(tmp_path):
    a, s = rheology.load(synthetic(str(tmp_path)))
    summ = rheology.summarise(a, s)
    assert summ['blocks_complete'] == 5 and summ['last_step'] == 60
    assert summ['records_per_block'] == [5.0] * 5
    q = summ['quantities']
    # eta_r = 1 + (sigma_h + sigma_c)_xy / gamma_dot over block means 2.5 .. 6.5
    assert q['eta_r']['value'] == pytest.approx(4.5, rel=1e-14)
    assert q['eta_r']['error'] == pytest.approx(math.sqrt(2.5 / 5), rel=1e-12)
    assert q['eta_h']['value'] == pytest.approx(4.0, rel=1e-14)
    assert q['eta_c']['value'] == pytest.approx(0.5, rel=1e-14) and q['eta_c']['error'] == pytest.approx(0, abs=1e-14)
    assert q['phi_core']['value'] == pytest.approx(0.4)
    assert q['gamma_dot_core']['value'] == pytest.approx(1.0)
    assert q['mu']['value'] == pytest.approx(4.5 / 2.0)       # tau / p
    assert q['I_v']['value'] == pytest.approx(0.5)             # gamma_dot / p
    assert np.allclose(summ['profiles']['velocity'], 0.5)
    assert np.allclose(summ['profiles']['y'], (np.arange(NB) + 0.5) * 10 / NB)


def test_incomplete_block_and_window(tmp_path):
    a, s = rheology.load(synthetic(str(tmp_path), last_step=58))
    summ = rheology.summarise(a, s)
    assert summ['blocks_complete'] == 4
    assert summ['quantities']['eta_r']['value'] == pytest.approx(1 + np.mean([1.5, 2.5, 3.5, 4.5]))
    w = rheology.with_window(a, 0.1, 0.4, 2)       # strains: 10 steps discarded, 2 blocks of 20
    assert (w['discard_step'], w['block_steps'], w['blocks']) == (10, 20, 2)
    summ = rheology.summarise(w, s)
    assert summ['blocks_complete'] == 2
    assert summ['quantities']['eta_r']['value'] == pytest.approx(1 + np.mean([2.0, 4.0]))   # blocks of 2
    with pytest.raises(ValueError):
        rheology.with_window(a, 0.1, 0.001, 2)


def test_strain_windows(tmp_path):
    a, s = rheology.load(synthetic(str(tmp_path)))
    b = rheology.strain_windows(a, s, 0.1, ['eta_h', 'eta_c'])
    # every window of the run from strain 0, discarded records included (the first: 1 + 1e3)
    assert b['strain_start'] == pytest.approx([0.0, 0.1, 0.2, 0.3, 0.4, 0.5])
    assert b['eta_h'] == pytest.approx([1001.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    assert b['eta_c'][1:] == pytest.approx([0.5] * 5)


def test_json_compare_and_contacts(tmp_path):
    d = synthetic(str(tmp_path))
    a, s = rheology.load(d)
    summ = rheology.summarise(a, s)
    with open(os.path.join(d, 'summary.json'), 'w') as f:
        json.dump(rheology.as_json(a, summ), f)
    assert rheology.compare(summ, os.path.join(d, 'summary.json')) == []
    summ['quantities']['eta_r']['value'] *= 1 + 1e-9
    assert rheology.compare(summ, os.path.join(d, 'summary.json'))[0].startswith('eta_r value')
    assert rheology.differs(None, float('nan')) is False
    lines = rheology.summary_lines(d, summ)
    assert lines[0].endswith('5 of 5 blocks complete (last step 60)') and len(lines) == 1 + len(rheology.NAMES)


def test_no_rheology(tmp_path):
    write_series(str(tmp_path / 'series.h5'), {'step': [1], 'time': [0.1]})
    with pytest.raises(rheology.NoRheology):
        rheology.load(str(tmp_path))


def test_contact_statistics(tmp_path):
    n = 10
    write_series(str(tmp_path / 'series.h5'),
                 {'step': np.arange(n), 'time': np.arange(n) * 0.5, 'contacts_pair': np.full(n, 4),
                  'contacts_wall': np.full(n, 1), 'contacts_sliding': np.where(np.arange(n) > 5, 5, 0),
                  'contact_overlap_over_roughness': np.arange(n) * 0.1}, {'shear_rate': -2.0})
    c = rheology.contact_statistics(str(tmp_path), 5.0)        # strain = time * 2 > 5: records 6..9
    assert c['records'] == 4 and c['pair_contacts'] == 4 and c['wall_contacts'] == 1
    assert c['sliding_fraction'] == 1.0
    assert c['largest_overlap_over_h_r_max'] == pytest.approx(0.9)


def test_records_helpers(tmp_path):
    run = dict(friction=0.5, dt=2e-3, eps_bar=0.05, roughness=5e-3, box=[8, 20, 8], cells_per_radius=4,
               solid_fraction_bulk=0.4, seed=1)
    assert rheology.stick_number(run) == pytest.approx(2e-3 / (3.5 * 0.5 * 0.05 * 5e-3))
    assert rheology.stick_number(dict(run, friction=0)) == 0.0
    assert rheology.setup_key(run) == ((8, 20, 8), 4, 0.4, 1, 0.05, 5e-3)
    p = tmp_path / 'r1' / 'summary.json'
    p.parent.mkdir()
    p.write_text(json.dumps({'complete': True, 'run': run, 'quantities': {'eta_r': {'value': 2, 'error': 0.1}}}))
    q = tmp_path / 'r2' / 'summary.json'
    q.parent.mkdir()
    q.write_text(json.dumps({'complete': True}))
    recs = rheology.load_records([str(p), str(q)])
    assert [r[0] for r in recs] == ['r1']


def mixture(outdir, walls=False):
    """The synthetic series as a mixture of two species (radii 1 and 1.4, 30 and 10 spheres):
    species 1 carries 0.3 of every stress and phi, species 2 0.7; the pair counts are the ideal
    mixture's expected counts exactly (n_b (N_b - delta_ab)/N_b times the references' shells), so
    every g_ab is 1. walls: the shells given as sampled volumes (species/pair_volumes) instead."""
    attrs = dict(ATTRS, species=2.0, radial_width=0.05, species_radius_1=1.0, species_radius_2=1.4,
                 species_count_1=30.0, species_count_2=10.0)
    synthetic(outdir, attrs=attrs)
    path = os.path.join(outdir, 'series.h5')
    cols, _ = rheology.series.read(outdir)
    n, nr = len(cols['step']), 20
    share = np.array([0.3, 0.7])
    refs = np.tile([6.0, 4.0], (n, 1))
    k = np.arange(1, nr + 1)
    shell = 4.0 / 3.0 * math.pi * 0.05 ** 3 * (k ** 3 - (k - 1) ** 3)
    volume = 4.0 / 3.0 * math.pi * np.array([1.0, 1.4]) ** 3
    phi = 0.4 * share
    counts = np.zeros((n, 2, 2, nr))
    volumes = np.zeros((n, 2, 2, nr))
    for a in range(2):
        for b in range(2):
            density = phi[b] / volume[b] * ([30.0, 10.0][b] - (a == b)) / [30.0, 10.0][b]
            volumes[:, a, b] = refs[:, a, None] * shell * (0.8 if walls else 1.0)
            counts[:, a, b] = density * volumes[:, a, b]
    cols.update({'species/stress_hydro': cols['core/stress_hydro'][:, None, :] * share[None, :, None],
                 'species/stress_contact': cols['core/stress_contact'][:, None, :] * share[None, :, None],
                 'species/solid_fraction': np.tile(phi, (n, 1)), 'species/references': refs,
                 'species/profile_solid_fraction': cols['profiles/solid_fraction'][:, None, :] * share[None, :, None],
                 'species/pair_counts': counts})
    if walls:
        cols['species/pair_volumes'] = volumes
    write_series(path, cols, attrs)
    return outdir


@pytest.mark.parametrize('walls', [False, True])
def test_species(tmp_path, walls):
    d = mixture(str(tmp_path), walls)
    a, s = rheology.load(d)
    summ = rheology.summarise(a, s)
    sp = summ['species']
    q = summ['quantities']
    # the species' shares add up to the pooled quantities, 0.3 and 0.7 of them
    assert sum(sp['quantities']['eta_r-1']['value']) == pytest.approx(q['eta_r']['value'] - 1, rel=1e-14)
    assert sp['quantities']['eta_c']['value'] == pytest.approx([0.15, 0.35], rel=1e-14)
    assert sum(sp['quantities']['N2/tau']['value']) == pytest.approx(q['N2/tau']['value'], rel=1e-14)
    assert sum(sp['quantities']['phi_core']['value']) == pytest.approx(q['phi_core']['value'], rel=1e-14)
    assert np.allclose(np.sum(sp['profiles']['solid_fraction'], axis=0), summ['profiles']['solid_fraction'], rtol=1e-14)
    assert np.allclose(sp['profiles']['number_density'][1], 0.28 / (4.0 / 3.0 * math.pi * 1.4 ** 3), rtol=1e-14)
    # the ideal mixture's counts give g_ab = 1, with no scatter over the blocks
    assert np.allclose(sp['pair_distribution']['g'], 1.0, rtol=1e-12)
    assert np.allclose(sp['pair_distribution']['g_error'], 0.0, atol=1e-12)
    # summary.json round trip with the species object; a changed g is found
    with open(os.path.join(d, 'summary.json'), 'w') as f:
        json.dump(rheology.as_json(a, summ), f)
    assert rheology.compare(summ, os.path.join(d, 'summary.json')) == []
    sp['pair_distribution']['g'][1, 0, 3] *= 1 + 1e-9
    assert rheology.compare(summ, os.path.join(d, 'summary.json'))[0].startswith('species pair_distribution/g')


def test_species_figure(tmp_path):
    from fdsusp import plots
    d = mixture(str(tmp_path / 'mix'))
    a, s = rheology.load(d)
    plots.run_figures([(d, a, s, rheology.summarise(a, s))], str(tmp_path / 'plots'))
    assert os.path.exists(os.path.join(str(tmp_path / 'plots'), 'mix_species.png'))
