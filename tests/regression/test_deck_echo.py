"""Invariant: the deck reader reads what the deck says, whatever the namelist syntax, and the
effective deck it echoes at the top of the run log is a deck that reads back into the same
configuration (doc/INPUT.md "The effective deck"; doc/DESIGN.md "The deck": each group is read
into its derived type by qualifying the deck's names, and the echo drops the qualifier again).
A deck written with the syntax users write (mixed case, several variables on a line, comments, a
quoted string holding '=', '!' and a variable's name, whole arrays, array sections and single
elements, logicals as F, inline particles with velocities and loads) is read into the values it
states (checked in the echo), and its echo, run as a deck, echoes itself again line for line
(a fixed point) and records the same deck in its checkpoint (/deck, attribute for attribute).
The rate, given as &domain shear_rate (its older name), is echoed once, as &shear rate; a deck
with an oscillatory &shear protocol (mixed case) echoes its protocol, amplitude and period and no
rate, and its echo is a fixed point too.
Exact checks: the echo prints every double with 17 significant digits, which reads back into the
same double, so no tolerance applies."""
import os
import re
import fdsusp_testlib as T

DECK = """! lubrication dynamics, no grid: the reader is what is tested, not the flow
&Domain BOX = 8.0, 8.0, 8.0, y_boundary = 'Lees-Edwards'   ! comment: shear_rate = 99
  Shear_Rate = 0.5 /
&fluid model = 'NONE' /
&time dt = 2.5e-3, steps = 2 /
&output directory = '{out}', progress_every = 1,
  series_every=1 /
&run title = 'deck: dt = 9, ! not a comment, "quoted"' /
&particles number = 3, motion = 'free'
  position(:,1) = 1.5, 3.2, 3.2
  position(:,2) = 4.0, 3.2, 3.2, position(1,3) = 3.0, position(2:3,3) = 1.0, 1.25
  external_force(:,2) = 0.0, 0.25, 0.0
  external_torque(3,1) = -0.125
/
&contact roughness = 1e-2, friction = 0.3, implicit = F, neighbour_skin = 0.25 /
&lubrication outer_cutoff = 1.5, skin = 0.3 /
"""

EXPECTED = {  # group, variable: the value the echo must show
    ("domain", "box"): [8.0, 8.0, 8.0], ('domain', 'y_boundary'): 'lees-edwards',
    ('shear', 'rate'): [0.5], ('fluid', 'model'): 'none', ('time', 'dt'): [2.5e-3],
    ('time', 'steps'): [2], ('run', 'title'): 'deck: dt = 9, ! not a comment, "quoted"',
    ('particles', 'number'): [3], ('contact', 'roughness'): [1e-2], ('contact', 'friction'): [0.3],
    ('contact', 'implicit'): 'F', ('contact', 'neighbour_skin'): [0.25],
    ('lubrication', 'outer_cutoff'): [1.5], ('lubrication', 'skin'): [0.3],
    ('particles', 'position(:,1)'): [1.5, 3.2, 3.2], ('particles', 'position(:,2)'): [4.0, 3.2, 3.2],
    ('particles', 'position(:,3)'): [3.0, 1.0, 1.25],
    ('particles', 'external_force(:,2)'): [0.0, 0.25, 0.0],
    ('particles', 'external_torque(:,1)'): [0.0, 0.0, -0.125],
}


def echo(out):
    """The effective deck of a run log, as lines."""
    lines = out.splitlines()
    first = lines.index(next(l for l in lines if l.startswith('# effective deck')))
    last = lines.index('# end of effective deck')
    return lines[first + 1:last]


def items(lines):
    """{(group, variable): value text} of echoed lines."""
    found, group = {}, ''
    for line in lines:
        m = re.match(r'\s*&(\w+)', line)
        if m:
            group = m.group(1).lower()
            continue
        m = re.match(r'\s*([A-Za-z_]\w*(?:\([^)]*\))?)\s*=\s*(.*?),?\s*$', line)
        if m:
            found[(group, m.group(1).lower())] = m.group(2)
    return found


def value(text):
    """A namelist value as Python: a string (delimiters off, doubled ones undone) or the list of
    numbers (repeat counts 'n*v' expanded)."""
    text = text.strip().rstrip(',')
    if text[:1] in '"\'':
        return text[1:-1].replace(text[0] * 2, text[0])
    numbers = []
    try:
        for v in filter(str.strip, text.split(',')):
            n, _, v = v.rpartition('*')
            numbers += [float(v)] * int(n or 1)
    except ValueError:
        return text
    return numbers


def main():
    d = T.scratch('deck_echo')
    _, out, _ = T.run(T.write_deck(d, 'first.nml', DECK.format(out='first')), d)
    first = echo(out)
    shown = items(first)
    for key, want in EXPECTED.items():
        got = value(shown.get(key, 'missing'))
        T.check(got == want, '%s %s: the echo shows %r (deck: %r)' % (key[0], key[1], got, want))
    T.check(not any(k[0] == 'particles' and k[1].startswith(('velocity', 'omega')) for k in shown),
            'the echo leaves out the inline arrays that are all zero (velocity, omega)')
    T.check(not any('%' in line for line in first), 'no qualified name (GROUP_group%...) left in the echo')

    T.check(not any(k == ('domain', 'shear_rate') for k in shown),
            'the rate is echoed once, as &shear rate (not as its older name &domain shear_rate)')
    fixed_point(d, first, 'first', 'again')

    # a protocol (&shear, doc/INPUT.md): its variables read case-blind, an oscillation's rate not
    # echoed (it follows from amplitude and period), the echo again a fixed point
    _, out, _ = T.run(T.write_deck(d, 'protocol.nml', DECK.format(out='protocol').replace(
        "  Shear_Rate = 0.5 /", "/\n&Shear Protocol = 'Oscillatory', strain_amplitude = 0.5, PERIOD = 6.283185307179586 /")), d)
    protocol = echo(out)
    shown = items(protocol)
    for key, want in {('shear', 'protocol'): 'oscillatory', ('shear', 'strain_amplitude'): [0.5],
                      ('shear', 'period'): [6.283185307179586], ('shear', 'control'): 'rate'}.items():
        got = value(shown.get(key, 'missing'))
        T.check(got == want, '%s %s: the echo shows %r (deck: %r)' % (key[0], key[1], got, want))
    T.check(('shear', 'rate') not in shown, 'an oscillation\'s rate is not echoed')
    fixed_point(d, protocol, 'protocol', 'protocol_again')
    T.finish()


def fixed_point(d, first, name, again_name):
    """The echo FIRST of the run into d/NAME, read as a deck (only the output directory changed to
    AGAIN_NAME), echoes itself line for line and records the same deck in its checkpoint."""
    again = '\n'.join(re.sub(r'DIRECTORY=.*', 'DIRECTORY="%s",' % again_name, line) for line in first) + '\n'
    _, out2, _ = T.run(T.write_deck(d, again_name + '.nml', again), d)
    second = echo(out2)
    differ = [(a, b) for a, b in zip(first, second) if a != b]
    T.check(len(first) == len(second) and [a for a, _ in differ] == [l for l in first if 'DIRECTORY=' in l],
            '%s: the echo read as a deck echoes itself: %d lines, only the directory differs (%s)'
            % (name, len(second), differ[:2]))
    T.compare_h5(os.path.join(d, name, 'checkpoint.h5'), os.path.join(d, again_name, 'checkpoint.h5'),
                 '%s: the checkpoints of the deck and of its echo' % name, rtol=0,
                 skip=('deck@output.directory', 'wall_time'))


if __name__ == '__main__':
    main()
