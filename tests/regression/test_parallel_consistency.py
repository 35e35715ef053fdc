"""Invariant: the decomposition does not change the answer. 1, 2 and 3 ranks run 20 steps of a
fully three-dimensional sheared flow (manufactured forcing between moving walls, 16^3 cells) and
must give the same u, v, w, p to 1e-10. The solvers run to a relative tolerance of 1e-12: the
multigrid smoothers (SOR) differ between decompositions, so results agree only to the solver
tolerance times the condition of the step (O(1e3) here): 1e-10 absolute on O(1) fields."""
import os
import numpy as np
import fdsusp_testlib as T

DECK = """&domain box = 3.2, 3.2, 3.2, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, velocity_tolerance = 1e-12, pressure_tolerance = 1e-12 /
&time dt = 0.005, steps = 20 /
&output directory = 'out', progress_every = 10 /
&verification manufactured_solution = .true. /
"""
fields = {}
for n in (1, 2, 3):
    d = T.scratch('parallel_%d' % n)
    deck = T.write_deck(d, 'p.nml', DECK)
    status, out, err = T.run(deck, d, np_ranks=n)
    print([l for l in out.splitlines() if l.startswith('grid:')][0])
    fields[n] = T.read_h5(os.path.join(d, 'out', 'checkpoint.h5'), ['u', 'v', 'w', 'p'])
scale = max(np.abs(fields[1][k]).max() for k in ('u', 'v', 'w'))
T.check(scale > 0.5, 'the flow is not trivial (max |u| = %.2f)' % scale)
for n in (2, 3):
    for k in ('u', 'v', 'w', 'p'):
        diff = np.abs(fields[n][k] - fields[1][k]).max()
        T.check(diff <= 1e-10, '%d ranks vs 1: max |%s difference| = %.2e <= 1e-10' % (n, k, diff))
T.finish()
