"""Invariant: a run that goes wrong stops with a diagnostic and never destroys its last good
checkpoint (doc/DESIGN.md "Errors": runtime guards). The velocity is poisoned with NaN at
step 12 through the test-only option -fault_nan_step (a stand-in for any blow-up); the guard
checks the fluid velocity, pressure and the particle state after every step. Asserted, on 2
ranks with one particle: non-zero exit status 5 at step 12, one message naming the step and the
quantity, failed_state.h5 written beside checkpoint.h5, and checkpoint.h5 still the good one of
step 10 (checkpoint_every = 10), from which a restart runs on cleanly to step 14 without the
fault; series.h5 holds the steps up to the failure.
Second guard: a sphere driven into the lower wall by an external force (no contacts, no
lubrication) stops the run (status 5) once its centre is half a radius from the wall, with a
message naming the particle and the wall, and failed_state.h5.
Third guard: a linear solver that does not converge stops the run (status 3) with one message
naming the solver, its KSP reason and iterations, and the last good checkpoint survives: the
run of the first guard is restarted from its step-14 checkpoint with the pressure solver capped
at one iteration (-fluid_solver krylov -p_ksp_max_it 1, a stand-in for a diverging or stagnating solve).
Fourth guard: a contact overlap beyond h_r (see the fourth case); its failed_state.h5 holds the
contact history like any checkpoint.
Fifth guard: the default path, whose fluid solves are direct (nothing to fail to converge), still
has one iterative solve, the particles' 6N system: a pair of spheres 0.1a apart couples it through
lubrication, and with that solve capped at one iteration (-particles_ksp_max_it 1, a stand-in for a
solve that fails) the run stops (status 4) with one message naming the solve and its KSP reason,
and no checkpoint is written over the good one.
Sixth: the first guard in lubrication dynamics (a NaN velocity of particle 1 between two series
records), where on several ranks each rank looks at its own spheres: 1 and 2 ranks stop alike."""
import os
import numpy as np
import fdsusp_testlib as T

DECK = """&domain box = 3.2, 6.4, 3.2, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, initial_flow = 'shear' /
&time dt = 1e-3, steps = {steps} /
&output directory = 'out', progress_every = 1, checkpoint_every = 10 /
&particles number = 1, position(:,1) = 1.6, 3.2, 1.6 /
"""
d = T.scratch('runtime_guard')
deck = T.write_deck(d, 'g.nml', DECK.format(steps=20))
status, out, err = T.run(deck, d, np_ranks=T.RANKS, args=['-fault_nan_step', '12'], expect_ok=False)
messages = [l for l in err.splitlines() if l.startswith('fdsusp:')]
T.check(status == 5, 'the run stops with status 5 (got %d)' % status)
T.check(len(messages) == 1 and 'step 12' in messages[0] and 'velocity' in messages[0],
        'one message naming the step and the quantity: %s' % messages[:1])
T.check(os.path.exists(os.path.join(d, 'out', 'failed_state.h5')), 'failed_state.h5 written')
ck = os.path.join(d, 'out', 'checkpoint.h5')
step = int(T.h5_attr(ck, 'step'))
u = T.read_h5(ck, ['u'])['u']
T.check(step == 10 and np.isfinite(u).all(), 'checkpoint.h5 is still the good one of step %d, finite' % step)
s = T.series(os.path.join(d, 'out'))
T.check(s['step'].max() <= 12, 'series.h5 ends at the failure (last step %d)' % s['step'].max())
deck = T.write_deck(d, 'g.nml', DECK.format(steps=14))
status, out, err = T.run(deck, d, np_ranks=T.RANKS, args=['-restart', ck], expect_ok=False)
T.check(status == 0 and 'finished at step 14' in out, 'restart from the kept checkpoint runs to step 14 (status %d)' % status)
os.replace(ck, os.path.join(d, 'good.h5'))
deck = T.write_deck(d, 'g.nml', DECK.format(steps=30))
status, out, err = T.run(deck, d, np_ranks=T.RANKS, args=['-restart', 'good.h5', '-fluid_solver', 'krylov', '-p_ksp_max_it', '1'], expect_ok=False)
messages = [l for l in err.splitlines() if l.startswith('fdsusp:')]
T.check(status == 3 and len(messages) == 1 and 'p solver diverged' in messages[0] and 'KSPConvergedReason -3' in messages[0],
        'a pressure solve that does not converge stops the run: status %d, %s' % (status, messages[:1]))
T.check(not os.path.exists(ck) and int(T.h5_attr(os.path.join(d, 'good.h5'), 'step')) == 14,
        'no checkpoint was written over the good one (good.h5 still at step 14)')

d = T.scratch('runtime_guard_wall')
deck = T.write_deck(d, 'w.nml', """&domain box = 3.2, 6.4, 3.2, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 0 /
&time dt = 1e-3, steps = 200 /
&output directory = 'out', progress_every = 10 /
&lubrication model = 'none' /
&particles number = 1, position(:,1) = 1.6, 1.3, 1.6, external_force(:,1) = 0, -3000, 0 /
""")
status, out, err = T.run(deck, d, expect_ok=False)
messages = [l for l in err.splitlines() if l.startswith('fdsusp:')]
T.check(status == 5 and len(messages) == 1 and 'particle 1' in messages[0] and 'wall' in messages[0],
        'a sphere pushed through the wall stops the run: status %d, %s' % (status, messages[:1]))
T.check(os.path.exists(os.path.join(d, 'out', 'failed_state.h5')), 'failed_state.h5 written')

# Fourth guard: two rough spheres (h_r = 0.01 a, soft k_n = 1e3 prescribed, no lubrication) driven
# together by +-20 (the force that overlaps them by h_r is k_n h_r^(3/2) = 1): the overlap passes
# h_r after some tens of steps and the run stops (status 5) with one message naming both particles and
# the overlap, failed_state.h5 beside the checkpoint of a step before, which stays the good one.
d = T.scratch('runtime_guard_overlap')
deck = T.write_deck(d, 'o.nml', """&domain box = 6.4, 6.4, 6.4, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 0 /
&time dt = 1e-3, steps = 200 /
&output directory = 'out', progress_every = 10, checkpoint_every = 5 /
&lubrication model = 'none' /
&particles number = 2, position(:,1) = 2.2, 3.2, 3.2, position(:,2) = 4.21, 3.2, 3.2,
  external_force(:,1) = 20, 0, 0, external_force(:,2) = -20, 0, 0 /
&contact roughness = 0.01, normal_stiffness = 1e3 /
""")
status, out, err = T.run(deck, d, np_ranks=T.RANKS, expect_ok=False)
messages = [l for l in err.splitlines() if l.startswith('fdsusp: fatal')]
T.check(status == 5 and len(messages) == 1 and 'particle 1 and particle 2' in messages[0] and 'exceeds' in messages[0],
        'an overlap beyond h_r stops the run: status %d, %s' % (status, messages[:1]))
T.check(os.path.exists(os.path.join(d, 'out', 'failed_state.h5')), 'failed_state.h5 written')
# the failed state holds what a checkpoint holds (one state bundle, mod_checkpoint): with it the
# contact history
failed_path = os.path.join(d, 'out', 'failed_state.h5')
failed = T.h5_contents(failed_path) if os.path.exists(failed_path) else {}
T.check('contacts@count' in failed and 'lambda_u' in failed,
        'failed_state.h5 holds Lambda and the contact history (%s)' % sorted(failed))
ck = os.path.join(d, 'out', 'checkpoint.h5')
T.check(os.path.exists(ck) and int(T.h5_attr(ck, 'step')) % 5 == 0 and np.isfinite(T.read_h5(ck, ['u'])['u']).all(),
        'the last good checkpoint is kept (step %s)' % (T.h5_attr(ck, 'step') if os.path.exists(ck) else None))

# The same guard in lubrication dynamics, the pair across the two ranks' slab face (z = Lz/2 on 2
# ranks): on several ranks each rank evaluates the contacts of its own spheres (mod_ld_local), and
# the largest overlap and its pair are reduced over the ranks, so the run stops at the same step,
# with the same message, as on one rank.
d = T.scratch('runtime_guard_overlap_ld')
deck = T.write_deck(d, 'o.nml', """&domain box = 6.4, 6.4, 6.4, y_boundary = 'walls', shear_rate = 0 /
&fluid model = 'none' /
&time dt = 1e-3, steps = 200 /
&output directory = 'out', progress_every = 10 /
&lubrication model = 'none' /
&particles number = 2, position(:,1) = 3.2, 3.2, 2.2, position(:,2) = 3.2, 3.2, 4.21,
  external_force(:,1) = 0, 0, 20, external_force(:,2) = 0, 0, -20 /
&contact roughness = 0.01, normal_stiffness = 1e3 /
""")
stops = []
for ranks in sorted({1, max(2, T.RANKS)}):
    status, out, err = T.run(deck, d, np_ranks=ranks, expect_ok=False)
    messages = [l for l in err.splitlines() if l.startswith('fdsusp: fatal')]
    stops.append(messages[0] if len(messages) == 1 and status == 5 else 'status %d, %s' % (status, messages[:1]))
T.check(len(set(stops)) == 1 and 'particle 1 and particle 2' in stops[0],
        'lubrication dynamics: the overlap across a slab face stops 1 and %d ranks alike: %s' % (max(2, T.RANKS), stops))

# The runtime guard in lubrication dynamics on several ranks, where the local sets are the state
# between steps (mod_ld_local) and each rank looks at its own spheres: particle 1 poisoned at step
# 12, between two series records (every 5 steps), stops 1 and 2 ranks alike (status 5, one message
# naming the particle), and failed_state.h5 holds the poisoned velocity. Particle 1 sits in the upper
# slab: on 2 ranks rank 1 owns it, finds the fault, describes it for every rank and writes its row
# of failed_state.h5 (the replicated particles are released after the first step).
d = T.scratch('runtime_guard_nan_ld')
deck = T.write_deck(d, 'n.nml', """&domain box = 6.4, 6.4, 6.4, y_boundary = 'walls', shear_rate = 1 /
&fluid model = 'none' /
&time dt = 1e-3, steps = 20 /
&output directory = 'out', progress_every = 10, series_every = 5 /
&lubrication model = 'none' /
&particles number = 2, position(:,1) = 3.2, 3.2, 4.21, position(:,2) = 3.2, 3.2, 2.2 /
&contact roughness = 0.01 /
""")
stops = []
for ranks in sorted({1, max(2, T.RANKS)}):
    status, out, err = T.run(deck, d, np_ranks=ranks, args=['-fault_nan_step', '12'], expect_ok=False)
    messages = [l for l in err.splitlines() if l.startswith('fdsusp:')]
    failed = os.path.join(d, 'out', 'failed_state.h5')
    poisoned = os.path.exists(failed) and np.isnan(T.read_h5(failed, ['particles/velocity'])['particles/velocity'][0, 0])
    stops.append(messages[0] if len(messages) == 1 and status == 5 and poisoned else
                 'status %d, %s, failed_state.h5 poisoned: %s' % (status, messages[:1], poisoned))
    if os.path.exists(failed):
        os.remove(failed)
T.check(len(set(stops)) == 1 and 'step 12' in stops[0] and 'particle 1 is not finite' in stops[0],
        'lubrication dynamics: the guard stops 1 and %d ranks alike, failed_state.h5 poisoned: %s'
        % (max(2, T.RANKS), stops))

d = T.scratch('runtime_guard_particle_solve')
PAIR = """&domain box = 6.4, 6.4, 6.4, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, initial_flow = 'shear' /
&time dt = 1e-3, steps = {steps} /
&output directory = 'out', progress_every = 1, checkpoint_every = 5 /
&particles number = 2, position(:,1) = 2.15, 3.2, 3.2, position(:,2) = 4.25, 3.2, 3.2 /
&lubrication model = 'full' /
"""
deck = T.write_deck(d, 'p.nml', PAIR.format(steps=5))
status, out, err = T.run(deck, d, np_ranks=T.RANKS)
ck = os.path.join(d, 'out', 'checkpoint.h5')
os.replace(ck, os.path.join(d, 'good.h5'))
deck = T.write_deck(d, 'p.nml', PAIR.format(steps=10))
status, out, err = T.run(deck, d, np_ranks=T.RANKS, args=['-restart', 'good.h5', '-particles_ksp_max_it', '1'],
                         expect_ok=False)
messages = [l for l in err.splitlines() if l.startswith('fdsusp:')]
T.check(status == 4 and len(messages) == 1 and 'particle system solve failed' in messages[0]
        and 'reason -3' in messages[0],
        'a particle solve that does not converge stops the run: status %d, %s' % (status, messages[:1]))
T.check(not os.path.exists(ck) and int(T.h5_attr(os.path.join(d, 'good.h5'), 'step')) == 5,
        'no checkpoint was written over the good one (good.h5 still at step 5)')
T.finish()
