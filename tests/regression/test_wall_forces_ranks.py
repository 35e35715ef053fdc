"""Invariant: the walls' forces on the spheres (the series' wall_force_contact and
wall_force_lubrication, the walls' share of the wall stress) are the whole system's on any number
of ranks, in both models. On the ranks' local sets (mod_ld_local) each rank evaluates the wall
contacts and links of its own spheres: their explicit forces are summed over the ranks with the
contact statistics, and the implicit contacts' update after the solve adds the part of the own
spheres' wall contacts, which must be summed too (ld_local_contacts_update). Before that, a sphere
pressed onto the lower wall in the second rank's slab left its implicit part out of the column
(1.02 of 24.3 at 2 ranks, the DNS).
Scene: the three spheres of test_contact_restart (friction 0.5, prescribed k_n), two pressed
together, the third pressed onto the lower wall, which moves; the third sits in the upper half of
z, so that on 2 and 3 ranks another rank than rank 0 owns it; the DNS and lubrication dynamics
(&fluid model = 'none') between walls, with full lubrication. 1 rank against 2 and 3, every step.
Tolerance: the ranks sum the forces in another order and the 6N solve's inner products too
(test_fd_local_set, test_ld_rank_independence: 1e-12 and below); 1e-10 of the largest."""
import os
import numpy as np
import fdsusp_testlib as T

DECK = """&domain box = 6.4, 6.4, 6.4, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 1 /
&fluid {fluid} /
&time dt = 1e-3, steps = 20 /
&output directory = 'out', progress_every = 10 /
&particles number = 3,
  position(:,1) = 3.2, 2.2, 3.2, external_force(:,1) = 0, 18.84955592153876, 0,
  position(:,2) = 3.2, 4.206, 3.2, external_force(:,2) = 0, -18.84955592153876, 0,
  position(:,3) = 0.3, 1.006, 5.0, external_force(:,3) = 0, -18.84955592153876, 0 /
&contact roughness = 0.01, normal_stiffness = 1e5, friction = 0.5 /
&lubrication model = 'full' /
"""
MODELS = {'dns': "reynolds = 0.01, initial_flow = 'shear'", 'ld': "model = 'none'"}
COLUMNS = ['wall_force_contact', 'wall_force_lubrication', 'particles/velocity']
TOL = 1e-10

for model, fluid in MODELS.items():
    series = {}
    for n in (1, 2, 3):
        d = T.scratch('wall_forces_%s_%d' % (model, n))
        status, out, err = T.run(T.write_deck(d, 'w.nml', DECK.format(fluid=fluid)), d, np_ranks=n)
        if n > 1:
            T.check("on the ranks' local sets" in out, '%s, %d ranks: the step on the local sets' % (model, n))
        series[n] = T.series(os.path.join(d, 'out'))
    ref = series[1]
    T.check(np.all(ref['contacts_wall'] == 1) and np.abs(ref['wall_force_contact']).max() > 1.0,
            '%s: a wall contact at every step (wall force up to %.1f)' % (model, np.abs(ref['wall_force_contact']).max()))
    for n in (2, 3):
        for k in COLUMNS:
            scale = np.abs(ref[k]).max()
            diff = np.abs(series[n][k] - ref[k]).max() / scale
            T.check(diff <= TOL, '%s, %d ranks vs 1: %s within %.1e of its largest (%.3g) <= %.0e'
                    % (model, n, k, diff, scale, TOL))
T.finish()
