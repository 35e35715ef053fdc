"""Invariant: a restart continues the checkpoint's physics (doc/INPUT.md "Restart: what must match,
what may change"). The checkpoint records its deck (group /deck, one attribute per variable); a
deck that differs in a variable that must match is refused before any work, with exit status 2
and one message naming the checkpoint, the deck's group and variable, and both values, and the
checkpoint is left bitwise as it was; a deck that differs only in variables that may change runs,
and the run log names each change. Covered here: with a resolved fluid dt, reynolds, shear_rate,
body_force, viscous_theta, manufactured_solution (refused) and steps, pressure_tolerance (logged);
in lubrication dynamics with contacts and &rheology the sphere radius, motion, an external force,
friction, roughness, the lubrication model and cut-off, the &contact group itself (refused),
neighbour_skin and steps (logged), and dt, which with &rheology is refused naming dt (before, the
refusal named the statistics' window). A branch (-branch) from the same checkpoint takes other
friction, roughness, lubrication cut-off and an external force, drops or adds the &contact group,
each change named in the log ('branch: ...'), and still refuses dt and radius; a restart refused
for friction names -branch. A checkpoint written before /deck existed (the group
deleted) still restarts, the log saying which variables cannot be checked, and its root attributes
dt, reynolds and shear_rate are still checked. Exact checks (message text, bytes, exit status):
the values compared are the doubles the decks were read into, so no tolerance applies."""
import itertools
import os
import shutil
import fdsusp_testlib as T

DNS = """&domain box = 3.2, 3.2, 3.2, cells_per_radius = 5, shear_rate = 1 /
&fluid reynolds = 0.01 /
&time dt = 0.005, steps = 4 /
&output directory = '{out}', progress_every = 1 /
"""
LD = """&domain box = 6.4, 6.4, 6.4, y_boundary = 'lees-edwards', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 0.002, steps = 4 /
&output directory = '{out}', progress_every = 1 /
&particles number = 2, position(:,1) = 2, 3.2, 3.2, position(:,2) = 4.5, 3.2, 3.2 /
&contact roughness = 0.01, friction = 0.3 /
&lubrication outer_cutoff = 1 /
&rheology discard_strain = 0.004, average_strain = 0.004, blocks = 1 /
"""


def base(d, text):
    """Run the deck from the start into d/base; return its checkpoint's path and bytes."""
    T.run(T.write_deck(d, 'base.nml', text.format(out='base')), d)
    path = os.path.join(d, 'base', 'checkpoint.h5')
    return path, open(path, 'rb').read()


def refused(d, cases):
    """Each case (ckpt, checkpoint bytes, name, deck text, words, how), a restart (how: or a branch)
    from ckpt with this deck, is refused before any work, naming words. The cases of a call run at
    the same time, four at a time (a refused run spends its time on MPI start-up), each with a
    deck and an output directory of its own (r_N.nml, again_N), all reading the same checkpoint."""
    runs = []
    for ckpt, before, name, text, words, how in cases:
        k = next(COUNT)
        T.write_deck(d, 'r_%d.nml' % k, text.format(out='again_%d' % k))
        runs.append(dict(deck='r_%d.nml' % k, cwd=d, args=[how, ckpt], expect_ok=False, out='again_%d' % k))
    results = T.run_many([{key: v for key, v in r.items() if key != 'out'} for r in runs], cores=4)
    for (ckpt, before, name, text, words, how), run, (status, out, err) in zip(cases, runs, results):
        messages = [line for line in err.splitlines() if line.startswith('fdsusp:') and 'warning' not in line]
        T.check(status == 2, '%s: refused with status %d == 2' % (name, status))
        T.check(len(messages) == 1 and all(w in messages[0] for w in words),
                '%s: one message naming %s: %s' % (name, ', '.join(words), messages[:1]))
        T.check(not any(line.startswith('step ') for line in out.splitlines())
                and not os.path.exists(os.path.join(d, run['out'])), '%s: no step taken, no output directory left' % name)
        T.check(open(os.path.join(d, ckpt), 'rb').read() == before, '%s: the checkpoint is bitwise as it was' % name)


COUNT = itertools.count()


def accepted(d, ckpt, name, text, notes, how='-restart'):
    """A restart (how: or a branch) from ckpt with this deck runs to its end and the log's lines
    of the restart ('restart:', 'branch:') hold each of notes."""
    shutil.rmtree(os.path.join(d, 'again'), ignore_errors=True)
    T.write_deck(d, 'r.nml', text.format(out='again'))
    status, out, err = T.run('r.nml', d, args=[how, ckpt], expect_ok=False)
    T.check(status == 0 and 'finished at step' in out, '%s: accepted, runs to its end (status %d)' % (name, status))
    for note in notes:
        T.check(any(note in line for line in out.splitlines() if line.startswith(how[1:] + ':')),
                '%s: the log says "%s"' % (name, note))
    return out


# ---- resolved fluid, no particles ----
d = T.scratch('restart_physics_dns')
ckpt, before = base(d, DNS)
rel = os.path.join('base', 'checkpoint.h5')
refused(d, [(rel, before, 'DNS ' + name, text, [rel, 'group ' + words[0]] + words[1:], '-restart')
            for name, text, words in [
    ('dt', DNS.replace('dt = 0.005', 'dt = 0.0025'), ['&time', 'variable dt', 'dt = 5.0E-03', 'dt = 2.5E-03']),
    ('reynolds', DNS.replace('reynolds = 0.01', 'reynolds = 0.1'),
     ['&fluid', 'variable reynolds', 'reynolds = 1.0E-02', 'reynolds = 1.0E-01']),
    ('shear_rate', DNS.replace('shear_rate = 1', 'shear_rate = 2'),
     ['&domain', 'variable shear_rate', 'shear_rate = 1,', 'shear_rate = 2:']),
    ('body_force', DNS.replace('reynolds = 0.01', 'reynolds = 0.01, body_force = 0.5, 0, 0'),
     ['&fluid', 'variable body_force', 'body_force = 0, 0, 0', 'body_force = 5.0E-01, 0, 0']),
    ('viscous_theta', DNS.replace('reynolds = 0.01', 'reynolds = 0.01, viscous_theta = 1'),
     ['&fluid', 'variable viscous_theta', 'viscous_theta = 5.0E-01', 'viscous_theta = 1:']),
    ('manufactured_solution', DNS + '&verification manufactured_solution = .true. /\n',
     ['&verification', 'variable manufactured_solution']),
]])
accepted(d, rel, 'DNS steps and pressure_tolerance',
         DNS.replace('steps = 4', 'steps = 6').replace('reynolds = 0.01', 'reynolds = 0.01, pressure_tolerance = 1e-8'),
         ['steps = 4 to steps = 6', 'pressure_tolerance = 1.0E-06 to pressure_tolerance = 1.0E-08'])

# a checkpoint written before /deck: restarts, says what it cannot check, and still checks dt
old = os.path.join(d, 'old.h5')
with open(old, 'wb') as f:
    f.write(before)
with T.h5py.File(old, 'r+') as f:
    del f['deck']
old_bytes = open(old, 'rb').read()
refused(d, [('old.h5', old_bytes, 'checkpoint without /deck, dt', DNS.replace('dt = 0.005', 'dt = 0.0025'),
             ['old.h5', 'group &time', 'variable dt'], '-restart')])
out = accepted(d, 'old.h5', 'checkpoint without /deck', DNS.replace('steps = 4', 'steps = 6'),
               ['does not record', '&fluid viscous_theta', 'cannot be checked'])
T.check(not any('&time dt' in line and 'does not record' in line for line in out.splitlines()),
        'checkpoint without /deck: dt is checked from its root attribute, not listed as unchecked')

# ---- lubrication dynamics with contacts and statistics ----
d = T.scratch('restart_physics_ld')
ckpt, before = base(d, LD)
refused(d, [(ckpt, before, 'lubrication dynamics ' + name, text, [ckpt, 'group ' + words[0]] + words[1:], '-restart')
            for name, text, words in [
    ('dt with &rheology', LD.replace('dt = 0.002', 'dt = 0.001'), ['&time', 'variable dt', '2.0E-03', '1.0E-03']),
    ('radius', LD.replace('number = 2,', 'number = 2, radius = 0.9,'),
     ['&particles', 'variable radius', 'radius = 1,', 'radius = 9.0E-01']),
    ('motion', LD.replace('number = 2,', "number = 2, motion = 'fixed',"),
     ['&particles', 'variable motion', "'free'", "'fixed'"]),
    ('external force', LD.replace('number = 2,', 'number = 2, external_force(:,2) = 0.1, 0, 0,'),
     ['&particles', 'variable external_force(:,2)', 'external_force(:,2) = 1.0E-01, 0, 0']),
    ('friction', LD.replace('friction = 0.3', 'friction = 0.5'),
     ['&contact', 'variable friction', 'friction = 3.0E-01', 'friction = 5.0E-01']),
    ('roughness', LD.replace('roughness = 0.01', 'roughness = 0.02'), ['&contact', 'variable roughness']),
    ('lubrication model', LD.replace('outer_cutoff = 1', "outer_cutoff = 1, model = 'none'"),
     ['&lubrication', 'variable model', "'full'", "'none'"]),
    ('lubrication cut-off', LD.replace('outer_cutoff = 1', 'outer_cutoff = 0.8'),
     ['&lubrication', 'variable outer_cutoff']),
    ('contacts dropped', LD.replace('&contact roughness = 0.01, friction = 0.3 /\n', ''),
     ['&contact', 'had contacts']),
]] + [
    # -branch: statistics begun at the checkpoint's step are still protected: their contact shell
    # follows the roughness
    (ckpt, before, 'branch of other roughness into begun statistics', LD.replace('roughness = 0.01', 'roughness = 0.02'),
     ['group &rheology', 'variable contact_shell', 'start afresh'], '-branch')])
accepted(d, ckpt, 'lubrication dynamics steps and neighbour_skin',
         LD.replace('steps = 4', 'steps = 6').replace('friction = 0.3', 'friction = 0.3, neighbour_skin = 0.3'),
         ['steps = 4 to steps = 6', 'neighbour_skin = 2.0E-01 to neighbour_skin = 3.0E-01'])

# ---- -branch: the checkpoint's state, this deck's contact and lubrication physics ----
# (a branch into begun statistics: refused above)
# the branches' statistics begin after the branch point (step 4): they start afresh. TRUNK runs
# to step 4, each branch on to step 12
TRUNK = LD.replace('discard_strain = 0.004', 'discard_strain = 0.02')
BRANCH = TRUNK.replace('steps = 4', 'steps = 12')
NO_CONTACTS = '&contact roughness = 0.01, friction = 0.3 /\n'
ckpt, before = base(d, TRUNK)
accepted(d, ckpt, 'branch: friction, roughness, cut-off, an external force',
         BRANCH.replace('friction = 0.3', 'friction = 0.5').replace('roughness = 0.01', 'roughness = 0.02')
               .replace('outer_cutoff = 1', 'outer_cutoff = 0.8')
               .replace('number = 2,', 'number = 2, external_force(:,2) = 0.1, 0, 0,'),
         ['friction = 3.0E-01 to friction = 5.0E-01', 'roughness = 1.0E-02 to roughness = 2.0E-02',
          'outer_cutoff = 1 to outer_cutoff = 8.0E-01', 'external_force(:,2) = 0, 0, 0 to external_force(:,2) = '
          '1.0E-01, 0, 0', 'may change on a branch'], how='-branch')
accepted(d, ckpt, 'branch: contacts dropped', BRANCH.replace(NO_CONTACTS, ''),
         ["the checkpoint's run had contacts, this one has none"], how='-branch')
with T.h5py.File(os.path.join(d, 'again', 'checkpoint.h5'), 'r') as f:
    T.check(int(f.attrs['step'][0]) == 12 and 'contacts' not in f,
            'branch: contacts dropped: its checkpoint at step 12 holds no springs')
refused(d, [(ckpt, before, 'branch ' + name, text, [ckpt, 'group ' + words[0]] + words[1:], '-branch')
            for name, text, words in [
    ('dt', BRANCH.replace('dt = 0.002', 'dt = 0.001'), ['&time', 'variable dt']),
    ('radius', BRANCH.replace('number = 2,', 'number = 2, radius = 0.9,'), ['&particles', 'variable radius']),
]] + [
    # a restart refused for what a branch may change says so
    (ckpt, before, 'restart of other friction points to -branch', BRANCH.replace('friction = 0.3', 'friction = 0.5'),
     ['variable friction', 'or branch from the checkpoint (-branch CHECKPOINT'], '-restart')])
ckpt, before = base(d, TRUNK.replace(NO_CONTACTS, ''))
out = accepted(d, ckpt, 'branch: contacts added', BRANCH, ["the checkpoint's run had no contacts"], how='-branch')
T.check(not any('does not record' in line for line in out.splitlines()),
        'branch: contacts added: the contact variables the checkpoint lacks are not called unchecked')
T.finish()
