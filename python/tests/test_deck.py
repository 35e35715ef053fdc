"""fdsusp.deck: decks written from Python values, read back, and judged by fdsusp itself."""
import glob
import os
import subprocess

import numpy as np
import pytest

from fdsusp import deck, run


def test_values():
    assert deck.value(True) == '.true.' and deck.value(False) == '.false.'
    assert deck.value(np.bool_(True)) == '.true.'
    assert deck.value(3) == '3' and deck.value(np.int64(3)) == '3'
    assert deck.value(2e-3) == '0.002' and deck.value(20.0) == '20.0' and deck.value(1e-5) == '1e-05'
    assert deck.value(np.float64(0.1)) == '0.1'
    assert deck.value("it's") == "'it''s'"
    assert deck.value((8, 20, 8)) == '8, 20, 8'
    assert deck.value(np.array([1.5, 2.0])) == '1.5, 2.0'
    assert deck.value([8.0, 1.6000000000000003], '%g') == '8, 1.6'
    assert deck.text({'time': {'dt': 5e-3, 'steps': 3}}, float_format='%g') == '&time dt = 0.005, steps = 3 /\n'


def test_text_layout():
    t = deck.text([('domain', {'box': (8, 20, 8), 'y_boundary': 'walls', 'shear_rate': 1}),
                   ('fluid', {'model': None, 'reynolds': 0.01}),
                   ('contact', {'implicit': None})], comment=['first', 'second'])
    assert t == ("! first\n! second\n&domain box = 8, 20, 8, y_boundary = 'walls', shear_rate = 1 /\n"
                 "&fluid reynolds = 0.01 /\n&contact /\n")
    assert deck.text({'time': {'dt': 1e-3}}) == '&time dt = 0.001 /\n'


def test_long_group_wrapped():
    many = {'number': 40}
    for i in range(1, 41):
        many['position(:,%d)' % i] = [0.1 * i + 1 / 3, 2 / 3, 1 / 7]
    t = deck.text([('particles', many), ('time', {'dt': 1e-3})])
    lines = t.splitlines()
    assert len(lines) > 10 and max(len(l) for l in lines) <= deck.WIDTH
    assert lines[0].startswith('&particles number = 40,') and lines[-2].endswith(' /') and lines[-1] == '&time dt = 0.001 /'
    assert deck.parse(t) == [('particles', many), ('time', {'dt': 1e-3})]


def test_round_trip():
    groups = [('domain', {'box': [7.5, 20, 7.5], 'cells_per_radius': 4, 'y_boundary': 'lees-edwards'}),
              ('particles', {'number': 2, 'position(:,1)': [2.9, 4, 4], 'position(:,2)': [5.1, 4, 4]}),
              ('run', {'title': "a 'quoted', / title = x ! not a comment", 'max_wall_hours': 0.1 + 0.2}),
              ('contact', {'friction': 1 / 3, 'implicit': False})]
    back = deck.parse(deck.text(groups, comment='c'))
    assert back == groups       # floats exactly: shortest repr


def test_parse_namelist_forms():
    text = """! comment
    &Domain box = 8  8 8   ! blanks separate values too
            cells_per_radius=4,
            y_boundary = "walls" /
    &time dt = 1d-3, steps = 2 /
    &lubrication model = 'full' /"""
    assert deck.parse(text) == [('domain', {'box': [8, 8, 8], 'cells_per_radius': 4, 'y_boundary': 'walls'}),
                                ('time', {'dt': 1e-3, 'steps': 2}), ('lubrication', {'model': 'full'})]
    with pytest.raises(ValueError):
        deck.parse('&time dt = 1 ')


def test_parse_shipped_decks(root):
    paths = glob.glob(os.path.join(root, 'input', '**', '*.nml'), recursive=True)
    assert len(paths) > 10
    for p in paths:
        with open(p) as f:
            groups = deck.parse(f.read())
        assert groups, p
        # written again and read back: the same groups
        assert deck.parse(deck.text(groups)) == groups, p


def test_fdsusp_accepts_and_refuses(tmp_path, fdsusp_binary):
    binary = fdsusp_binary
    good = [('domain', {'box': (8, 8, 8), 'cells_per_radius': 4}), ('time', {'dt': 1e-3, 'steps': 0}),
            ('output', {'directory': 'out'})]
    deck.write(str(tmp_path / 'good.nml'), deck.text(good))
    p = run.run('good.nml', cwd=str(tmp_path), binary=binary, timeout=120)
    assert p.returncode == 0 and 'finished at step 0' in p.stdout
    # eight spheres, their positions and velocities given exactly: a group far longer than a line
    spheres = {'number': 8, 'motion': 'frozen'}
    for i in range(8):
        spheres['position(:,%d)' % (i + 1)] = [2 + 4 * (i & 1) + 1 / 3, 2 + 2 * (i >> 1 & 1) * 2 + 1 / 7, 2 + 4 * (i >> 2) + 1 / 9]
        spheres['velocity(:,%d)' % (i + 1)] = [1 / 3, -1 / 7, 1 / 11]
    deck.write(str(tmp_path / 'long.nml'), deck.text(good + [('particles', spheres)]))
    assert len(deck.group('particles', spheres).replace('\n', '')) > 1024
    p = run.run('long.nml', cwd=str(tmp_path), binary=binary, timeout=120)
    assert p.returncode == 0 and 'finished at step 0' in p.stdout and '8 rigid spheres' in p.stdout, p.stderr
    bad = [(good[0][0], dict(good[0][1], no_such_key=1))] + good[1:]
    deck.write(str(tmp_path / 'bad.nml'), deck.text(bad))
    p = run.run('bad.nml', cwd=str(tmp_path), binary=binary, timeout=120)
    assert p.returncode != 0 and 'no_such_key' in p.stderr and 'unknown variable' in p.stderr
