"""Write the decks of the shear-reversal study (README.md): lubrication dynamics, Lees-Edwards cube
10a, equal rough spheres (eps_r 5e-3), phi 0.30/0.40/0.45, mu_d 0 and 0.5, rate 1 reversed every
strain G = 3. The contact stiffness and step keep the stick number at the friction study's 4.6
(doc/CONTACT.md): eps_bar 0.05 with dt 2e-3 at phi 0.30 (doc/data/friction_phi04's base), eps_bar
0.025 with dt 1e-3 at phi 0.40 and 0.45 (with 0.05 the overlap reached h_r/2 within the first 3
strains at phi 0.40); the frictionless runs take dt 2e-3 and the eps_bar of their phi."""
import os

G = 3.0
SEGMENTS = 11                     # the first (from the packing) and 10 after reversals: 33 strains
WINDOW = 6                        # &rheology over segments 2-6 (strains 3-18; the first pass ran 6)
here = os.path.dirname(os.path.abspath(__file__))
CASES = [(phi, eps_bar, mu, G, SEGMENTS, WINDOW, '') for phi, eps_bar in ((0.30, 0.05), (0.40, 0.025), (0.45, 0.025))
         for mu in (0.0, 0.5)]
# is strain 3 the steady state? phi 0.30 and 0.40 reversed every strain 6 (4 segments, 3 reversals, 24 strains)
CASES += [(phi, eps_bar, mu, 6.0, 4, 4, '_g6') for phi, eps_bar in ((0.30, 0.05), (0.40, 0.025)) for mu in (0.0, 0.5)]
for phi, eps_bar, mu, G, SEGMENTS, WINDOW, suffix in CASES:
    if True:
        dt = 2.0e-3 if (mu == 0 or eps_bar == 0.05) else 1.0e-3
        every = 5 if dt == 2.0e-3 else 10                     # a record every strain 0.01
        name = 'rev_mu%s_p%02d%s' % ('0' if mu == 0 else '05', round(100 * phi), suffix)
        per_g = round(G / dt)
        steps = SEGMENTS * per_g
        deck = f"""! Shear reversal in lubrication dynamics (issue 46 item 4): Lees-Edwards cube 10 a, equal spheres,
! phi {phi:.2f}, mu_d {mu}, rough spheres eps_r 5e-3 with eps_bar {eps_bar} (stick number 4.6 with friction),
! seed 3, rate 1 reversed every strain {G:g} ({per_g} steps of {dt:g}), {SEGMENTS} segments = {SEGMENTS * G:g} strains
! (doc/data/protocols/reversal/README.md). Run: bin/fdsusp doc/data/protocols/reversal/{name}.nml -continue
&domain box = 10, 10, 10, y_boundary = 'lees-edwards' /
&shear rate = 1.0, protocol = 'reversal', reversal_strain = {G:.1f} /
&fluid model = 'none' /
&time dt = {dt:g}, steps = {steps} /
&output directory = 'out/protocols/reversal/{name}', progress_every = 1500, series_every = {every}, checkpoint_every = {per_g // 3} /
&particles solid_fraction = {phi:.2f}, seed = 3 /
&contact roughness = 5.0e-3, friction = {mu}, eps_bar = {eps_bar} /
&rheology discard_strain = {G:.1f}, average_strain = {(WINDOW - 1) * G:.1f}, blocks = {WINDOW - 1} /
&run title = 'reversal: equal spheres, phi {phi:.2f}, mu_d {mu}' /
"""
        with open(os.path.join(here, name + '.nml'), 'w') as f:
            f.write(deck)
        print(name, dt, steps)
