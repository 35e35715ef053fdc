"""pairtraj: the final offset grows with roughness, and matches the hard-contact theory.

Invariants:
  1. (issue 3; JFM section 3, figure 3) contact forces are repulsive only, so a rough pair leaves
     on a streamline further out than it came in, the more so the larger the roughness:
     y_out(0) = 0.5 < y_out(1e-3) < y_out(1e-2), each step by more than 0.05 (measured
     0.21 and 0.35; a missing or attractive contact gives a difference of 0).
  2. Hard-contact limit (DaCunha & Hinch 1996; doc/METHOD.md §9.3): with a rigid roughness the pair
     leaves contact at theta = pi/2, rho = 2 + eps_r, and then follows the level set of the
     Batchelor-Green first integral through that point. Evaluating that first integral by
     quadrature of A(rho), B(rho) (an independent route: no time integration, no contact law)
     gives y(x = +6) = 0.70827 (eps_r = 1e-3) and 1.05522 (1e-2) (doc/VALIDATION_pair.md).
     The Hertz contact of the deck (eps_bar = 0.05: the roughness yields by ~5 %) must agree
     within 0.5 %; measured 0.073 % and 0.057 %.
  3. Hard-contact limit of the soft contact: as eps_bar -> 0 (stiffer roughness) pairtraj's
     offset must converge to the first-integral value: the relative difference decreases
     monotonically over eps_bar = 0.05, 0.01, 1e-3 and is below 2e-5 at 1e-3 (the reference
     values carry 5 digits, i.e. +-7e-6; measured 1.5e-6 and 4.1e-6).
  4. Hertz law and stiffness of JFM 2.17 and section 2.4: at the deepest overlap the normal
     force equals k_n |delta'|^{3/2} with k_n = 6 pi / (eps_bar h_r)^{3/2}, i.e.
     F_max = 6 pi ((h_r - gap_min)/(eps_bar h_r))^{3/2} (both taken at the same step end;
     tolerance 1e-9 relative, round-off of the printed values). The roughness yields by
     |delta'|/h_r ~ eps_bar (F/6 pi)^{2/3} ~ 5 %, as the paper intends.
"""
import math
from pairtraj_lib import run_deck, Checker

HARD_CONTACT = {"pair_eps1e-3": 0.70827, "pair_eps1e-2": 1.05522}

c = Checker()
y = {}
for name in ("pair_eps0", "pair_eps1e-3", "pair_eps1e-2"):
    summary, _ = run_deck(name)
    y[name] = summary["final_y"]
    if name != "pair_eps0":
        h_r = 1e-3 if name == "pair_eps1e-3" else 1e-2
        f_hertz = 6 * math.pi * ((h_r - summary["min_gap"]) / (0.05 * h_r)) ** 1.5
        rel = abs(summary["max_fc_normal"] / f_hertz - 1)
        c.check("%s: max F_n = k_n |delta'|^1.5 at the closest approach" % name, rel < 1e-9,
                "(F = %.6f, Hertz %.6f, |delta'|/h_r = %.4f)" %
                (summary["max_fc_normal"], f_hertz, (h_r - summary["min_gap"]) / h_r))
    print("%-14s final y = %.8f  min gap = %.4e  max F_n = %.3f" %
          (name, y[name], summary["min_gap"], summary["max_fc_normal"]))
c.check("offset grows with roughness: y(1e-3) - y(0) > 0.05", y["pair_eps1e-3"] - y["pair_eps0"] > 0.05)
c.check("offset grows with roughness: y(1e-2) - y(1e-3) > 0.05",
        y["pair_eps1e-2"] - y["pair_eps1e-3"] > 0.05)
for name, ref in HARD_CONTACT.items():
    rel = abs(y[name] / ref - 1)
    c.check("%s: within 0.5 %% of the hard-contact first-integral value %.5f" % (name, ref),
            rel < 5e-3, "(rel. diff %.2e)" % rel)
for name, ref in HARD_CONTACT.items():
    diffs = []
    for eb in ("0.05", "0.01", "1.0e-3"):
        summary, _ = run_deck(name, tag="%s_eb%s" % (name, eb), eps_bar=eb)
        diffs.append(abs(summary["final_y"] / ref - 1))
    print("%s: |y/y_hard - 1| at eps_bar = 0.05, 0.01, 1e-3: %s" %
          (name, ", ".join("%.2e" % d for d in diffs)))
    c.check("%s: converges to the hard-contact value as eps_bar -> 0" % name,
            diffs[0] > diffs[1] > diffs[2] and diffs[2] < 2e-5)
c.done()
