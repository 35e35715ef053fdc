"""Invariant: contacts do not chatter. In a contact-dominated sheared suspension no core stress
alternates from one record to the next: for every record k (from step 20 on) and every component
xx, yy, zz, xy of the core stresses Sigma^h (hydrodynamic), Sigma^c (contact) and their sum,
|s_{k+1} - 2 s_k + s_{k-1}| / 2 <= 0.5 % of the shear stress tau (the run's mean of
gamma_dot_core + Sigma^p_xy over the records from step 200 on). For a pure period-two
alternation s_k = m +- a the left side is 2a, the jump between consecutive records; a smooth
evolution gives the curvature dt^2 s'', which is far smaller (0.03 % here).

Scene: 56 rough frictional spheres (phi = 0.40, mu_d = 0.5, eps_r = 5e-3, eps_bar = 0.05, packed at
start, seed 3) in a 7a x 12a x 7a Couette cell at a/Delta = 4 with full lubrication, dt = 1.25e-3
(chatter number dt gamma_dot/eps_bar = 0.025, the largest the explicit scheme accepts), 400 steps
(strain 0.5), 2 ranks; 7 pair contacts at a time in the second half (3-4 of them sliding), the
contact stress Sigma^c_yy 11 % of tau. Measured (doc/CONTACT.md "Implicit contacts"): with implicit
contacts (the default) the largest value is 0.17 % (Sigma^c_yy and Sigma^h_yy at step 227, the
step a contact closes; their sum 0.04 %), with `&contact implicit = .false.` 2.6 % (Sigma^c_yy) and
above 0.5 % on every record from step ~250 on, growing: the period-two chatter of the explicit Hertz
force against the particles' one-step response. The tolerance 0.5 % is the issue's target (no
record of the demo alternates by more than 0.5 % of the shear stress): 3x the implicit worst case,
5x below the explicit one. The first 20 steps are left out: the impulsively started shear flow
(and the forward-Euler first step) is a smooth transient of large curvature there (2 % of tau at
step 2, below 1e-4 by step 20) that is not an alternation. The test also checks that the scene is
contact-dominated as described (at least 4 pair contacts and one sliding contact on average over
the second half, -Sigma^c_yy >= 5 % of tau), so that it keeps testing what it says.

`test_contact_chatter.py --explicit` runs the same scene with `&contact implicit = .false.`: it
must fail (it does: the proof that the test sees the chatter)."""
import os
import sys
import numpy as np
import fdsusp_testlib as T

EXPLICIT = '--explicit' in sys.argv[1:]
DECK = """&domain box = 7.0, 12.0, 7.0, cells_per_radius = 4, y_boundary = 'walls', shear_rate = 1.0 /
&fluid reynolds = 0.01, initial_flow = 'shear' /
&time dt = 1.25e-3, steps = 400 /
&output directory = 'out', progress_every = 100 /
&particles solid_fraction = 0.4, seed = 3 /
&contact roughness = 5.0e-3, friction = 0.5, implicit = {implicit} /
&lubrication model = 'full' /
&rheology discard_strain = 0.1, average_strain = 0.4, blocks = 2 /
"""
TOL = 5e-3
d = T.scratch('contact_chatter' + ('_explicit' if EXPLICIT else ''))
T.run(T.write_deck(d, 'deck.nml', DECK.format(implicit='.false.' if EXPLICIT else '.true.')), d, np_ranks=T.RANKS)
s = T.series(os.path.join(d, 'out'))
step = s['step']
h = s['core/stress_hydro'][:, :4]
c = s['core/stress_contact'][:, :4]
late = step > 200
tau = np.mean(s['core/shear_rate'][late] + h[late, 3] + c[late, 3])
print('scheme: %s contacts; tau = %.4f' % ('explicit' if EXPLICIT else 'implicit', tau))

# the scene is what the docstring says it is
pairs = s['contacts_pair'][late].mean()
sliding = s['contacts_sliding'][late].mean()
pressure = -c[late, 1].mean() / tau
T.check(pairs >= 4 and sliding >= 1 and pressure >= 0.05,
        'contact-dominated: %.1f pair contacts (>= 4), %.1f sliding (>= 1), -Sigma^c_yy = %.3f tau (>= 0.05)'
        % (pairs, sliding, pressure))

# no record alternates
inner = step[1:-1] >= 20
names = ['xx', 'yy', 'zz', 'xy']
for label, x in [('hydrodynamic', h), ('contact', c), ('total', h + c)]:
    jump = np.abs(x[2:] - 2 * x[1:-1] + x[:-2])[inner] / 2 / tau
    k, m = np.unravel_index(np.argmax(jump), jump.shape)
    worst = jump[k, m]
    above = np.count_nonzero(jump.max(axis=1) > TOL)
    T.check(worst <= TOL, '%s core stress: largest |second difference|/2 = %.4f %% of tau (Sigma_%s at step %d; '
            '%d records above %.1f %%) <= %.1f %%' % (label, 100 * worst, names[m], step[1:-1][inner][k], above,
                                                    100 * TOL, 100 * TOL))
T.finish()
