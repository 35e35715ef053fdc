"""Invariant: bad input stops the run before any work, with a non-zero status and one message that
names the file and the item at fault (group and variable for a deck). 'Before any work' is
checked by the absence of any time step in the log and of series.h5 in the output directory.
A deck that runs but is known to be inaccurate (close free pairs lagging, doc/VALIDATION.md §4.4)
is warned once before the first step.
A run refused at input checking leaves nothing it created: an output directory (and its parents)
made by the refused run is removed again when it holds nothing but the lock file, so a fresh
&output directory does not exist after the refusal (exact check, no tolerance)."""
import os
import shutil
import fdsusp_testlib as T

GOOD = """&domain box = 3.2, 3.2, 3.2, cells_per_radius = 5 /
&fluid reynolds = 0.01 /
&time dt = 0.005, steps = 4 /
&output directory = 'out', progress_every = 1 /
"""
d = T.scratch('bad_input')
# a good checkpoint to corrupt
T.run(T.write_deck(d, 'good.nml', GOOD), d)
ckpt = os.path.join(d, 'out', 'checkpoint.h5')
data = open(ckpt, 'rb').read()
with open(os.path.join(d, 'truncated.h5'), 'wb') as f:
    f.write(data[:len(data) // 2])
with open(os.path.join(d, 'not_a_directory'), 'w') as f:
    f.write('a file')
os.rename(os.path.join(d, 'out'), os.path.join(d, 'good_run'))
# a lubrication-dynamics checkpoint (&fluid model = 'none', Lees-Edwards), for the DNS to refuse
LD = GOOD.replace('cells_per_radius = 5', "cells_per_radius = 5, y_boundary = 'lees-edwards', shear_rate = 1") \
    .replace('reynolds = 0.01', "model = 'none'") + '&particles number = 1, position(:,1) = 1.6, 1.6, 1.6 /\n'
T.run(T.write_deck(d, 'ld.nml', LD), d)
os.rename(os.path.join(d, 'out'), os.path.join(d, 'ld_run'))
# a position file without particles (N = 0): nothing for lubrication dynamics to move
with T.h5py.File(os.path.join(d, 'empty_positions.h5'), 'w') as f:
    f.create_dataset('particles/position', data=T.np.zeros((0, 3)))

LDS = GOOD.replace('cells_per_radius = 5', "cells_per_radius = 5, y_boundary = 'lees-edwards'") \
    .replace('reynolds = 0.01', "model = 'none'") + '&particles number = 1, position(:,1) = 1.6, 1.6, 1.6 /\n'

cases = [
    # name, deck text (None: do not write), extra args, words the message must contain
    ('unknown variable', GOOD.replace('reynolds', 'reynold'), [], ['bad.nml', '&fluid', 'reynold', 'unknown variable']),
    ('value out of range', GOOD.replace('dt = 0.005', 'dt = -1'), [], ['bad.nml', '&time', 'dt', 'out of range']),
    ('wrong type', GOOD.replace('steps = 4', "steps = 'many'"), [], ['bad.nml', '&time', 'steps', 'cannot read']),
    ('unknown group', GOOD + '&fluidd reynolds = 1 /\n', [], ['bad.nml', '&fluidd', 'unknown group']),
    # the comma of the array section must not cut the name to '1)'
    ('bad value in an array section', GOOD + "&particles number = 1, position(:,1) = 1.6, 1.6, 1.6, "
     "motion = 'prescribed', velocity(:,1) = --0.1, 0, 0 /\n", [], ['bad.nml', '&particles', 'variable velocity', 'cannot read']),
    ('missing deck', None, [], ['bad.nml', 'does not exist']),
    ('periodic box with shear', GOOD.replace('cells_per_radius = 5', "cells_per_radius = 5, y_boundary = 'periodic'"),
     [], ['bad.nml', '&shear', 'rate', 'periodic']),
    ('periodic box with the older name of the rate', GOOD.replace('cells_per_radius = 5',
     "cells_per_radius = 5, y_boundary = 'periodic', shear_rate = 2"),
     [], ['bad.nml', '&domain', 'shear_rate', 'periodic']),
    ('fractional cell count', GOOD.replace('box = 3.2, 3.2, 3.2', 'box = 3.3, 3.2, 3.2'), [], ['bad.nml', '&domain', 'box(x)', 'whole number']),
    ('bad y_boundary', GOOD.replace('cells_per_radius = 5', "cells_per_radius = 5, y_boundary = 'wall'"), [], ['bad.nml', '&domain', 'y_boundary']),
    ('unwritable output directory', GOOD.replace("directory = 'out'", "directory = 'not_a_directory/out'"), [],
     ['bad.nml', '&output', 'directory', 'cannot be created']),
    ('truncated checkpoint', GOOD, ['-restart', 'truncated.h5'], ['truncated.h5', 'truncated']),
    ('missing checkpoint', GOOD, ['-restart', 'nowhere.h5'], ['nowhere.h5', 'does not exist']),
    ('unknown fluid solver', GOOD, ['-fluid_solver', 'fftt'], ['-fluid_solver', 'fftt', 'fft or krylov']),
    ('unknown FFT planner', GOOD, ['-fluid_fft_plan', 'fast'], ['-fluid_fft_plan', 'fast', 'estimate']),
    ('checkpoint from another grid', GOOD.replace('cells_per_radius = 5', 'cells_per_radius = 2.5'),
     ['-restart', 'good_run/checkpoint.h5'], ['good_run/checkpoint.h5', 'item cells', '16x16x16', '8x8x8']),
    ('checkpoint from another box', GOOD.replace('box = 3.2, 3.2, 3.2', 'box = 3.2, 6.4, 3.2').replace('cells_per_radius = 5', 'cells_per_radius = 5'),
     ['-restart', 'good_run/checkpoint.h5'], ['good_run/checkpoint.h5', 'item cells']),
    ('restart with another particle count', GOOD + '&particles number = 1, position(:,1) = 1.6, 1.6, 1.6 /\n',
     ['-restart', 'good_run/checkpoint.h5'], ['good_run/checkpoint.h5', '/particles', '0 particles', 'the deck 1']),
    ('not a checkpoint', GOOD, ['-restart', 'bad.nml'], ['bad.nml', 'cannot be opened as HDF5']),
    ('unknown particle motion', GOOD + "&particles number = 1, position(:,1) = 1.6, 1.6, 1.6, motion = 'stuck' /\n", [],
     ['bad.nml', '&particles', 'motion']),
    ('overlapping particles', GOOD.replace('3.2, 3.2, 3.2', '6.4, 6.4, 6.4') +
     '&particles number = 2, position(:,1) = 2, 3, 3, position(:,2) = 3.5, 3, 3 /\n', [],
     ['bad.nml', '&particles', 'position(:,1)', 'overlap']),
    ('particle through a wall', GOOD + '&particles number = 1, position(:,1) = 1.6, 0.5, 1.6 /\n', [],
     ['bad.nml', '&particles', 'position(:,1)', 'crosses a wall']),
    ('rough pair starting inside h_r/2', GOOD.replace('3.2, 3.2, 3.2', '6.4, 6.4, 6.4') +
     '&particles number = 2, position(:,1) = 2, 3.2, 3.2, position(:,2) = 4.004, 3.2, 3.2 /\n'
     '&contact roughness = 0.01 /\n', [],
     ['bad.nml', '&particles', 'position(:,1)', 'start at a gap of', 'h_r/2']),
    ('rough sphere touching a wall', GOOD.replace('3.2, 3.2, 3.2', '6.4, 6.4, 6.4') +
     '&particles number = 1, position(:,1) = 3.2, 1.0, 3.2 /\n&contact roughness = 0.01 /\n', [],
     ['bad.nml', '&particles', 'position(:,1)', 'wall gap', 'h_r/2']),
    ('explicit rough contacts that would chatter', GOOD.replace('3.2, 3.2, 3.2, cells_per_radius = 5 /',
                                                                '6.4, 6.4, 6.4, cells_per_radius = 5, shear_rate = 1 /') +
     '&particles number = 1, position(:,1) = 3.2, 3.2, 3.2 /\n&contact roughness = 0.01, implicit = .false. /\n', [],
     ['bad.nml', '&time', 'dt', 'chatter', 'largest stable dt here is  1.25E-03']),
    ('implicit rough contacts beyond the chatter numbers measured',
     GOOD.replace('3.2, 3.2, 3.2, cells_per_radius = 5 /', '6.4, 6.4, 6.4, cells_per_radius = 5, shear_rate = 1 /')
     .replace('dt = 0.005', 'dt = 0.02') +
     '&particles number = 1, position(:,1) = 3.2, 3.2, 3.2 /\n&contact roughness = 0.01 /\n', [],
     ['bad.nml', '&time', 'dt', 'free of chatter', 'largest dt measured stable here is  1.00E-02']),
    ('rough packing closer than h_r/2', GOOD.replace('3.2, 3.2, 3.2', '6.4, 6.4, 6.4') +
     '&particles solid_fraction = 0.1, packing_min_gap = 1e-3 /\n&contact roughness = 0.01 /\n', [],
     ['bad.nml', '&particles', 'packing_min_gap', 'h_r/2']),
    ('missing position file', GOOD + "&particles position_file = 'nowhere.h5' /\n", [],
     ['bad.nml', '&particles', 'position_file', 'does not exist']),
    ('position file without particles', GOOD + "&particles position_file = 'good_run/checkpoint.h5' /\n", [],
     ['good_run/checkpoint.h5', 'particles/position', 'missing']),
    ('smooth spheres without stiffness', GOOD + "&contact roughness = 0, friction = 0.3 /\n", [],
     ['bad.nml', '&contact', 'normal_stiffness', 'roughness = 0']),
    ('negative friction', GOOD + "&contact roughness = 0.01, friction = -0.1 /\n", [],
     ['bad.nml', '&contact', 'friction', 'out of range']),
    ('eps_bar rule without shear', GOOD.replace('cells_per_radius = 5', 'cells_per_radius = 5, shear_rate = 0') +
     "&contact roughness = 0.01 /\n", [], ['bad.nml', '&contact', 'normal_stiffness', 'shear_rate']),
    ('contact range beyond the periodic box', GOOD + "&contact roughness = 0.01, neighbour_skin = 0.5 /\n", [],
     ['bad.nml', '&domain', 'box(x)', 'neighbour_skin']),
    ('unknown lubrication model', GOOD + "&lubrication model = 'exact' /\n", [], ['bad.nml', '&lubrication', 'model']),
    ('lubrication cut-offs crossed', GOOD + "&lubrication outer_cutoff = 1e-5 /\n", [],
     ['bad.nml', '&lubrication', 'outer_cutoff', 'inner_cutoff']),
    # a/Delta 9: no table is shipped at that resolution (input/lubrication has 4-8 and 10)
    ('resolution with no lubrication table', GOOD.replace('3.2, 3.2, 3.2, cells_per_radius = 5', '4, 4, 4, cells_per_radius = 9') +
     '&particles number = 1, position(:,1) = 1.6, 1.6, 1.6 /\n', [], ['bad.nml', '&lubrication', 'model', 'no table']),
    ('lubrication table of another fictitious domain', GOOD +
     '&particles number = 1, position(:,1) = 1.6, 1.6, 1.6, radius_offset = 0.3 /\n', [],
     ['resolved_a5.h5', 'radius_offset']),
    ('lubricating pairs beyond the periodic box', GOOD + '&particles number = 2, position(:,1) = 0.8, 1.05, 0.8, ' +
     'position(:,2) = 2.4, 2.15, 2.4 /\n', [], ['bad.nml', '&lubrication', 'periodic length']),
    ('statistics without walls', GOOD.replace('cells_per_radius = 5', "cells_per_radius = 5, y_boundary = 'periodic', "
     "shear_rate = 0") + '&particles solid_fraction = 0.1 /\n&rheology /\n', [], ['bad.nml', '&rheology', 'walls']),
    ('statistics without particles', GOOD + '&rheology /\n', [], ['bad.nml', '&rheology', 'needs particles']),
    ('packing and inline particles', GOOD + '&particles solid_fraction = 0.1, number = 1, position(:,1) = 1.6, 1.6, 1.6 /\n',
     [], ['bad.nml', '&particles', 'solid_fraction', 'one way']),
    ('packing beyond the supported fraction', GOOD + '&particles solid_fraction = 0.65 /\n', [],
     ['bad.nml', '&particles', 'solid_fraction', 'out of range']),
    # lubrication dynamics (issue 30)
    ('unknown fluid model', GOOD.replace('reynolds = 0.01', "reynolds = 0.01, model = 'stokes'"), [],
     ['bad.nml', '&fluid', 'model', 'stokes']),
    ('lubrication dynamics without particles', GOOD.replace('reynolds = 0.01', "model = 'none'"), [],
     ['bad.nml', '&fluid', 'model', 'particles']),
    ('simple lubrication without a fluid', LD + "&lubrication model = 'simple' /\n", [],
     ['bad.nml', '&lubrication', 'model', 'simple']),
    ('pair cut-off beyond 20a', LD + "&lubrication outer_cutoff = 25 /\n", [],
     ['bad.nml', '&lubrication', 'outer_cutoff', 'out of range']),
    ('lubrication-dynamics step beyond the contact limit', LD.replace('dt = 0.005', 'dt = 0.05')
     .replace('3.2, 3.2, 3.2', '6.4, 6.4, 6.4').replace('1.6, 1.6, 1.6', '3.2, 3.2, 3.2') +
     '&contact roughness = 0.01 /\n', [], ['bad.nml', '&time', 'dt', 'largest dt measured stable here is  1.00E-02']),
    ('steady state without a fluid', LD.replace('steps = 4', 'steps = 4, steady_tolerance = 1e-3'), [],
     ['bad.nml', '&time', 'steady_tolerance', "model = 'resolved'"]),
    ('DNS restart from a lubrication-dynamics checkpoint', GOOD, ['-restart', 'ld_run/checkpoint.h5'],
     ['ld_run/checkpoint.h5', 'fluid_resolved', '&fluid model']),
    ('walls restart from a Lees-Edwards checkpoint', LD.replace("y_boundary = 'lees-edwards'", "y_boundary = 'walls'"),
     ['-restart', 'ld_run/checkpoint.h5'], ['ld_run/checkpoint.h5', 'lees_edwards_offset', 'y_boundary']),
    ('lubrication dynamics with an empty position file',
     LD.replace('&particles number = 1, position(:,1) = 1.6, 1.6, 1.6 /', "&particles position_file = 'empty_positions.h5' /"),
     [], ['bad.nml', '&particles', 'position_file', 'empty_positions.h5', 'holds no particles']),
    ('averaging blocks without records', GOOD + '&particles solid_fraction = 0.1 /\n'
     '&rheology average_strain = 0.01, blocks = 5 /\n', [],
     ['bad.nml', '&rheology', 'average_strain', 'series_every']),
    # &shear (doc/INPUT.md): the protocols of rate control
    ('rate under both names', GOOD.replace('cells_per_radius = 5', 'cells_per_radius = 5, shear_rate = 1') +
     '&shear rate = 1 /\n', [], ['bad.nml', '&shear', 'rate', 'shear_rate']),
    # stress control (doc/INPUT.md "&shear"): LDS, a lubrication-dynamics deck with one sphere
    ('unknown control', GOOD + "&shear control = 'strain' /\n", [], ['bad.nml', '&shear', 'control', 'strain']),
    ('stress under rate control', GOOD + "&shear stress = 2 /\n", [], ['bad.nml', '&shear', 'stress', "control = 'stress'"]),
    ('stress control without a stress', LDS + "&rheology /\n&shear control = 'stress' /\n", [],
     ['bad.nml', '&shear', 'stress', 'must be given']),
    # the DNS with particles takes stress control (the wall speed set by the walls' force balance,
    # doc/METHOD.md §7.4), with backward Euler as the fluid alone, and free or frozen spheres
    ('stress control in the DNS with Crank-Nicolson', GOOD + "&shear control = 'stress', stress = 2 /\n"
     "&particles number = 1, position(:,1) = 1.6, 1.6, 1.6 /\n", [], ['bad.nml', '&fluid', 'viscous_theta', 'must be 1']),
    ('stress control of prescribed spheres in the DNS', GOOD.replace('reynolds = 0.01', 'reynolds = 0.01, viscous_theta = 1')
     + "&shear control = 'stress', stress = 2 /\n&particles number = 1, position(:,1) = 1.6, 1.6, 1.6, "
     "motion = 'prescribed' /\n", [], ['bad.nml', '&particles', 'motion', "'stress'"]),
    ('a strain amplitude in a stress oscillation', LDS + "&rheology /\n&shear control = 'stress', stress = 2, "
     "protocol = 'oscillatory', strain_amplitude = 0.1, period = 1 /\n", [],
     ['bad.nml', '&shear', 'strain_amplitude', 'amplitude &shear stress']),
    ('a stress oscillation without a period', LDS + "&rheology /\n&shear control = 'stress', stress = 2, "
     "protocol = 'oscillatory' /\n", [], ['bad.nml', '&shear', 'period']),
    ('a stress reversal shorter than a step', LDS + "&rheology /\n&shear control = 'stress', stress = 2, "
     "protocol = 'reversal', reversal_strain = 1e-6 /\n", [], ['bad.nml', '&shear', 'reversal_strain', 'one step']),
    ('stress control, no particles and no walls', LDS.replace('&particles number = 1, position(:,1) = 1.6, 1.6, 1.6 /\n', '')
     + "&shear control = 'stress', stress = 2 /\n", [], ['bad.nml', '&shear', 'control', 'no stress can be measured']),
    ('stress control without statistics', LDS + "&shear control = 'stress', stress = 2 /\n", [],
     ['bad.nml', '&shear', 'control', '&rheology']),
    ('stress control with a zero reference rate', LDS + "&rheology /\n&shear control = 'stress', stress = 2, rate = 0 /\n",
     [], ['bad.nml', '&shear', 'rate', '> 0']),
    # steps of rate or stress (protocol 'steps')
    ('steps without levels', GOOD + "&shear protocol = 'steps' /\n", [], ['bad.nml', '&shear', 'levels', '2 ..']),
    ('step_at without steps', GOOD + "&shear step_at = 0, 1 /\n", [], ['bad.nml', '&shear', 'step_at', "'steps'"]),
    ('first step not at 0', GOOD + "&shear protocol = 'steps', levels = 2, step_at = 0.5, 1, step_level = 1, 2 /\n", [],
     ['bad.nml', '&shear', 'step_at(1)', 'must be 0']),
    ('steps not increasing', GOOD + "&shear protocol = 'steps', levels = 2, step_at = 0, 0, step_level = 1, 2 /\n", [],
     ['bad.nml', '&shear', 'step_at(2)', 'one step']),
    ('a level at rest counted in strain', GOOD + "&shear protocol = 'steps', levels = 2, step_at = 0, 1, "
     "step_level = 0, 2 /\n", [], ['bad.nml', '&shear', 'step_level(1)', 'never reaches']),
    ('more step values than levels', GOOD + "&shear protocol = 'steps', levels = 2, step_at = 0, 1, 2, "
     "step_level = 1, 2 /\n", [], ['bad.nml', '&shear', 'step_at', 'more values than levels']),
    ('unknown step_by', GOOD + "&shear protocol = 'steps', step_by = 'steps', levels = 2, step_at = 0, 1, "
     "step_level = 1, 2 /\n", [], ['bad.nml', '&shear', 'step_by', "'time'"]),
    ('a stress with stress steps', LDS + "&rheology /\n&shear control = 'stress', stress = 2, protocol = 'steps', "
     "levels = 2, step_at = 0, 1, step_level = 1, 2 /\n", [], ['bad.nml', '&shear', 'stress', 'step_level']),
    ('stress control of prescribed spheres', LDS.replace('1.6, 1.6, 1.6 /', "1.6, 1.6, 1.6, motion = 'prescribed' /")
     + "&rheology /\n&shear control = 'stress', stress = 2 /\n", [], ['bad.nml', '&particles', 'motion', "'stress'"]),
    ('unknown protocol', GOOD + "&shear protocol = 'creep' /\n", [], ['bad.nml', '&shear', 'protocol', 'creep']),
    ('amplitude without oscillation', GOOD + '&shear strain_amplitude = 0.1 /\n', [],
     ['bad.nml', '&shear', 'strain_amplitude', 'oscillatory']),
    ('period without oscillation', GOOD + "&shear protocol = 'reversal', reversal_strain = 1, period = 2 /\n", [],
     ['bad.nml', '&shear', 'period', 'oscillatory']),
    ('reversal strain without reversal', GOOD + '&shear reversal_strain = 1 /\n', [],
     ['bad.nml', '&shear', 'reversal_strain', 'reversal']),
    ('reversal strain shorter than a step', GOOD + "&shear protocol = 'reversal', reversal_strain = 0.004 /\n", [],
     ['bad.nml', '&shear', 'reversal_strain', 'one step']),
    ('non-positive period', GOOD + "&shear protocol = 'oscillatory', strain_amplitude = 0.1, period = 0 /\n", [],
     ['bad.nml', '&shear', 'period', 'out of range']),
    ('non-positive amplitude', GOOD + "&shear protocol = 'oscillatory', strain_amplitude = -0.1, period = 1 /\n", [],
     ['bad.nml', '&shear', 'strain_amplitude', 'out of range']),
    ('steady tolerance with a reversal', GOOD.replace('steps = 4', 'steps = 4, steady_tolerance = 1e-3') +
     "&shear protocol = 'reversal', reversal_strain = 1 /\n", [], ['bad.nml', '&time', 'steady_tolerance', 'reversal']),
    ('rate with an oscillation', GOOD + "&shear protocol = 'oscillatory', rate = 2, strain_amplitude = 0.1, period = 1 /\n",
     [], ['bad.nml', '&shear', 'rate', 'strain_amplitude']),
]
# Every run below starts in a directory of its own (d/case_N: the deck, and copies of the inputs
# made above under the same relative names), so that the runs are independent and T.run_many runs
# several at once: a refused run spends its ~0.5 s waiting on MPI start-up, not computing (4 at a
# time keep the 2 cores busy). Each case thus also starts without an output directory, so one case
# that ran cannot fail the next.
INPUTS = ('good_run/checkpoint.h5', 'ld_run/checkpoint.h5', 'truncated.h5', 'not_a_directory', 'empty_positions.h5')
runs = []


def case_run(deck_name, text, args):
    """A fresh directory holding the inputs and deck_name (text; None: no deck), and its run."""
    where = os.path.join(d, 'case_%d' % len(runs))
    for name in INPUTS:
        os.makedirs(os.path.dirname(os.path.join(where, name)), exist_ok=True)
        shutil.copy2(os.path.join(d, name), os.path.join(where, name))
    if text is not None:
        T.write_deck(where, deck_name, text)
    runs.append(dict(deck=deck_name, cwd=where, args=args, expect_ok=False))
    return where


for name, text, args, words in cases:
    case_run('bad.nml', text, args)

# A refused run leaves no directory it made: a fresh &output directory (two levels deep) of a run
# refused for its checkpoint, its position file or its lubrication table is gone afterwards; an
# existing directory stays (its lock file emptied: tests/regression/test_output_lock.py).
fresh_cases = [
    ('missing checkpoint', GOOD, ['-restart', 'nowhere.h5']),
    ('truncated checkpoint', GOOD, ['-restart', 'truncated.h5']),
    ('empty position file', LD.replace('&particles number = 1, position(:,1) = 1.6, 1.6, 1.6 /',
                                       "&particles position_file = 'empty_positions.h5' /"), []),
    ('table of another fictitious domain', GOOD + '&particles number = 1, position(:,1) = 1.6, 1.6, 1.6, '
     'radius_offset = 0.3 /\n', []),
]
for name, text, args in fresh_cases:
    case_run('fresh.nml', text.replace("directory = 'out'", "directory = 'fresh/run'"), args)

# A deck that runs but lets close free pairs lag (doc/VALIDATION.md §4.4) is warned once, before the
# first step; at dt = 1e-3 (dt^2/(Re Delta^2) = 1.6e-3 at a/Delta = 4) it is not.
PAIR = """&domain box = 8, 8, 8, cells_per_radius = 4 /
&fluid reynolds = 0.01 /
&time dt = {dt}, steps = 1 /
&output directory = 'out_pair' /
&lubrication model = 'full' /
&particles number = 2, position(:,1) = 2.9, 4, 4, position(:,2) = 5.1, 4, 4 /
"""
LAGS = (('2.5e-3', 1), ('1e-3', 0))
for dt, expected in LAGS:
    case_run('pair.nml', PAIR.format(dt=dt), [])

results = T.run_many(runs, cores=4)

for (name, text, args, words), run, (status, out, err) in zip(cases, runs, results):
    messages = [l for l in err.splitlines() if l.startswith('fdsusp:')]
    T.check(status != 0, '%s: exit status %d != 0' % (name, status))
    T.check(len(messages) == 1, '%s: one message (%d): %s' % (name, len(messages), messages[:1]))
    T.check(all(w in err for w in words), '%s: the message names %s' % (name, ', '.join(words)))
    T.check(not any(l.startswith('step ') for l in out.splitlines()) and
            not os.path.exists(os.path.join(run['cwd'], 'out', 'series.h5')), '%s: no time step was taken' % name)

k = len(cases)
for (name, text, args), run, (status, out, err) in zip(fresh_cases, runs[k:], results[k:]):
    where = run['cwd']
    T.check(status == 2 and not os.path.exists(os.path.join(where, 'fresh')),
            'refused (%s, status %d) into a fresh directory: the directory it made is removed (%s)'
            % (name, status, os.listdir(os.path.join(where, 'fresh', 'run'))
               if os.path.isdir(os.path.join(where, 'fresh', 'run'))
               else 'gone' if not os.path.exists(os.path.join(where, 'fresh')) else 'fresh/ left'))

k += len(fresh_cases)
for (dt, expected), (status, out, err) in zip(LAGS, results[k:]):
    lag = [l for l in err.splitlines() if 'separate too fast' in l]
    T.check(status == 0 and len(lag) == expected, 'free pair at dt %s: exit %d, %d lag warning(s), expected %d: %s'
            % (dt, status, len(lag), expected, lag))
T.finish()
