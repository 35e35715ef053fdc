"""pairtraj: the result is converged in the integrator tolerance (issue 3).

Invariant: halving rtol and atol changes the final offset by less than 1e-5 (issue tolerance),
for each of the five project decks (smooth, eps_r = 1e-3 and 1e-2, each also with mu_d = 0.3).
The Dormand-Prince 5(4) pair with rtol = 1e-10 keeps the local error near 1e-10 per step; the
non-smooth events (contact onset, Coulomb cap) lower the global order, which is why the check is
on the whole final value and not on an error estimate (measured changes 9e-11 .. 1.9e-7).
"""
from pairtraj_lib import run_deck, Checker

c = Checker()
for name in ("pair_eps0", "pair_eps1e-3", "pair_eps1e-3_mu03", "pair_eps1e-2", "pair_eps1e-2_mu03"):
    s1, _ = run_deck(name, tag=name + "_tol1", rtol="1.0e-10", atol="1.0e-13")
    s2, _ = run_deck(name, tag=name + "_tol2", rtol="5.0e-11", atol="5.0e-14")
    d = abs(s1["final_y"] - s2["final_y"])
    c.check("%-18s halving the tolerance changes y_final by < 1e-5" % name, d < 1e-5,
            "(%.12f vs %.12f, |d| = %.2e)" % (s1["final_y"], s2["final_y"], d))
c.done()
