"""Invariant: restart is exact. N steps in one run equal N/2 steps, a checkpoint, a restart and
N/2 steps: the checkpoint holds the complete state (u, v, w, p, the last pressure increment,
the warm start of the next Poisson solve, and the provisional velocities u*^n, u*^{n-1} whose
extrapolation starts the viscous solves), so the continued run repeats the same arithmetic and
agrees to round-off: every dataset and attribute of the two final checkpoints, and of the two
series.h5 (wall_time excepted), agrees to 1e-12 of its largest magnitude (at least 1; bitwise in
practice). The same holds when the checkpoint was written because the run received SIGTERM (exit
status 0), and SIGUSR1 through mpiexec on 2 ranks stops the run cleanly with a checkpoint too.
series.h5 of the continued run holds each step exactly once. The grid is 16 x 16 x 12 cells: nx /= nz
(a restart of such a grid was refused until 2026-11-27: the field shape was compared in C order)."""
import os
import shutil
import signal
import subprocess
import time
import numpy as np
import fdsusp_testlib as T

DECK = """&domain box = 3.2, 3.2, 2.4, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01 /
&time dt = 0.005, steps = {steps} /
&output directory = 'out', progress_every = {progress} /
&verification manufactured_solution = .true. /
"""
STATE = ['u', 'v', 'w', 'p', 'phi', 'u_star', 'v_star', 'w_star', 'u_star_old', 'v_star_old', 'w_star_old']


def compare(da, db, what):
    """Every dataset and attribute of the final checkpoints and of series.h5 (but wall_time)."""
    names = T.compare_h5(os.path.join(da, 'out', 'checkpoint.h5'), os.path.join(db, 'out', 'checkpoint.h5'),
                         what + ', checkpoint')
    T.check(all(n in names for n in STATE), '%s: the checkpoint holds the whole fluid state' % what)
    T.compare_h5(os.path.join(da, 'out', 'series.h5'), os.path.join(db, 'out', 'series.h5'), what + ', series',
                 skip=('wall_time',))
    sb = T.series(os.path.join(db, 'out'))
    T.check(np.array_equal(sb['step'], np.arange(1, len(sb['step']) + 1)),
            '%s: series steps 1..%d, each once' % (what, len(sb['step'])))


# 20 steps straight against 10 + restart + 10
a = T.scratch('restart_straight')
T.run(T.write_deck(a, 'd.nml', DECK.format(steps=20, progress=5)), a)
b = T.scratch('restart_split')
T.run(T.write_deck(b, 'd10.nml', DECK.format(steps=10, progress=5)), b)
T.check(int(T.h5_attr(os.path.join(b, 'out', 'checkpoint.h5'), 'step')[0]) == 10, 'checkpoint at step 10')
T.run(T.write_deck(b, 'd.nml', DECK.format(steps=20, progress=5)), b, args=['-restart', 'out/checkpoint.h5'])
compare(a, b, '20 steps vs 10 + restart + 10')

# SIGTERM in the middle of a long run, then continue 10 steps
c = T.scratch('restart_sigterm')
status, out = T.run_until_then_signal(T.write_deck(c, 'long.nml', DECK.format(steps=100000, progress=1)), c, 5)
T.check(status == 0, 'SIGTERM: exit status %d == 0' % status)
T.check('stopped by signal 15' in out, 'SIGTERM: the log says the run stopped on the signal')
k = int(T.h5_attr(os.path.join(c, 'out', 'checkpoint.h5'), 'step')[0])
T.check(k >= 5, 'SIGTERM: checkpoint written at step %d' % k)
T.run(T.write_deck(c, 'd.nml', DECK.format(steps=k + 10, progress=5)), c, args=['-restart', 'out/checkpoint.h5'])
e = T.scratch('restart_sigterm_reference')
T.run(T.write_deck(e, 'd.nml', DECK.format(steps=k + 10, progress=5)), e)
compare(e, c, 'SIGTERM at step %d + restart + 10 vs %d straight' % (k, k + 10))

# SIGUSR1 through mpiexec on 2 ranks
f = T.scratch('restart_sigusr1')
status, out = T.run_until_then_signal(T.write_deck(f, 'long.nml', DECK.format(steps=100000, progress=1)), f, 3,
                                      sig=signal.SIGUSR1, np_ranks=T.RANKS)
T.check(status == 0, 'SIGUSR1 on %d ranks: exit status %d == 0' % (T.RANKS, status))
T.check('stopped by signal 10' in out, 'SIGUSR1: the log says the run stopped on the signal')
k = int(T.h5_attr(os.path.join(f, 'out', 'checkpoint.h5'), 'step')[0])
T.check(k >= 3, 'SIGUSR1: checkpoint written at step %d' % k)

# SIGUSR1 during the set-up (after PetscInitialize, while the spheres are packed): the run still
# stops cleanly, after its first step (PETSc's own handler, in place until the set-up ended,
# aborted it)
g = T.scratch('restart_setup_signal')
deck = T.write_deck(g, 'pack.nml', """&domain box = 16, 20, 16, cells_per_radius = 2, shear_rate = 1 /
&time dt = 1e-3, steps = 100000 /
&output directory = 'out', progress_every = 1 /
&particles solid_fraction = 0.45, seed = 3, packing_sweeps = 4000 /
&lubrication model = 'none' /
""")
log = open(os.path.join(g, 'run.log'), 'w+')
p = subprocess.Popen(T.command(deck), cwd=g, env=T.ENV, stdout=log, stderr=subprocess.STDOUT, text=True)
t0 = time.time()
while time.time() - t0 < 120 and p.poll() is None and '# end of effective deck' not in open(log.name).read():
    time.sleep(0.01)
p.send_signal(signal.SIGUSR1)
during_setup = 'models:' not in open(log.name).read()
status = p.wait(timeout=300)
out = open(log.name).read()
T.check(during_setup, 'SIGUSR1 sent during the set-up (the deck read, no models line yet)')
T.check(status == 0 and 'stopped by signal 10 at step 1:' in out,
        'a signal during the set-up stops the run after its first step, status %d' % status)
T.finish()
