"""pairtraj: friction does not move the trajectory (issue 3; JFM section 3: "frictional or
frictionless particles result in hardly distinguishable trajectories").

Invariants:
  1. mu_d = 0.3 changes the final offset of the eps_r = 1e-2 pair by less than 2 % of the
     offset (issue tolerance; measured ~2e-6). The reason is physical: the tangential contact
     force only changes the pair's rotation, and a torque-free pair's relative translation
     couples to rotation only weakly (YB terms).
  2. Friction is really active: max |F_t| > 0.1 with mu_d = 0.3 and exactly 0 with mu_d = 0,
     and |F_t| <= mu_d |F_n| at every output (Coulomb cap, JFM 2.22; 1e-9 relative slack).
  3. (JFM figure 5) friction alters the normal stress differences during contact, in the
     compression quadrant: max over the contact of |N2*(0.3) - N2*(0)| > 1e-3, compared at the
     same theta.
"""
from pairtraj_lib import run_deck, interp, Checker

c = Checker()
s0, r0 = run_deck("pair_eps1e-2", tag="fr_mu0")
s3, r3 = run_deck("pair_eps1e-2_mu03", tag="fr_mu03")
rel = abs(s3["final_y"] - s0["final_y"]) / s0["final_y"]
c.check("mu_d = 0.3 changes the final offset by < 2 %", rel < 0.02,
        "(y = %.8f vs %.8f, rel. change %.2e)" % (s3["final_y"], s0["final_y"], rel))
c.check("frictional run has a tangential force > 0.1", s3["max_fc_tangential"] > 0.1,
        "(max |F_t| = %.3f)" % s3["max_fc_tangential"])
c.check("frictionless run has no tangential force", s0["max_fc_tangential"] == 0.0)
cap = max(r["fc_tangential"] - 0.3 * r["fc_normal"] * (1 + 1e-9) for r in r3)
c.check("Coulomb cap |F_t| <= mu_d |F_n| at every output", cap <= 1e-12, "(max excess %.2e)" % cap)
th0 = [r["theta"] for r in r0][::-1]
n20 = [r["N2star"] for r in r0][::-1]
dn2 = max(abs(r["N2star"] - interp(th0, n20, r["theta"])) for r in r3 if r["contact"] > 0)
c.check("friction changes N2* during contact by > 1e-3", dn2 > 1e-3, "(max |dN2*| = %.4f)" % dn2)
c.done()
