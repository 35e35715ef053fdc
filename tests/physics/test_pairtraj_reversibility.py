"""pairtraj: reversibility of the smooth pair (issue 3 acceptance).

Invariant: Stokes flow is reversible and the smooth pair's relative trajectory is symmetric under
x -> -x (Batchelor & Green 1972: the in-plane trajectory is a level set of a first integral that
depends on rho and sin(theta) only). Starting at (-6, 0.5, 0) the pair must therefore leave at
x = +6 with y = 0.5 exactly.
Tolerance 1e-4 (issue). The integrator's global error at the deck's rtol = 1e-10 is ~1e-8 (the
final offset moves by < 1e-8 between rtol 1e-9 and 1e-11), so 1e-4 leaves room only for a
physics or model error (e.g. a wrong sign in a coupling term gives errors of order 1e-2).
Also: the smooth pair never touches (no contact force), and z stays 0 (in-plane motion).
"""
from pairtraj_lib import run_deck, Checker

c = Checker()
summary, rows = run_deck("pair_eps0")
y_final = summary["final_y"]
c.check("final offset y(x=+6) = 0.5 within 1e-4", abs(y_final - 0.5) < 1e-4,
        "(y = %.12f, |dy| = %.2e)" % (y_final, abs(y_final - 0.5)))
c.check("final x = 6 exactly (1e-10)", abs(summary["final_x"] - 6.0) < 1e-10)
c.check("no contact force for smooth spheres", summary["max_fc_normal"] == 0.0)
c.check("motion stays in the shear plane (|z| < 1e-12)", max(abs(r["z"]) for r in rows) < 1e-12)
print("minimum gap of the smooth pair: %.4e" % summary["min_gap"])
c.done()
