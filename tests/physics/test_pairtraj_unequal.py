"""pairtraj for two spheres of different sizes (&pair size_ratio; doc/PAIRTRAJ_INPUT.md).

Sphere 1 has radius a = 1, sphere 2 radius lambda; start (-6, 0.5, 0), x_end = 6, rtol 1e-10.
Invariants:
  1. smooth pairs (eps_r = 0) at lambda = 1.4 and 2 are fore-aft symmetric: the final offset
     equals the initial 0.5 (|dy| < 1e-7: the symmetry is exact for any resistance functions,
     Stokes reversibility plus the mirror x -> -x; the integrator leaves ~4e-9 as for equal
     spheres) and y(x) = y(-x) along the path (1e-5: linear interpolation of records every 0.002
     strain, as test_pairtraj_symmetry); the pair's N1*, N2* are antisymmetric about theta = pi/2
     (the mirror flips S_xy, time reversal flips S; 1e-4 of max |N|).
  2. relabelling: radii (1, 2) from (-6, 0.5, 0) and radii (1, 1/2) from (-3, 0.25, 0) are the
     same physical pair with the spheres swapped and lengths halved (and, by the point symmetry
     r -> -r of the linear shear, the same r(t)); with the contact scaled alike (h_r halved,
     eps_bar doubled: the same k_ij in physical units, doc/PAIRTRAJ_INPUT.md), rough and frictional
     (eps_r = 1e-2, mu_d = 0.3): r_A(t) = 2 r_B(t), N1*, N2* of the pair equal, sphere 1's
     per-sphere values and Omega_z equal sphere 2's of the other run, contact forces 4x (force
     scale a^2). Tolerance 2e-6 on positions, 1e-5 on N*, Omega (the two runs take different
     steps at rtol 1e-10; halving the tolerance moves rough offsets by up to 2e-7,
     test_pairtraj_tolerance; observed 7e-8 and 9e-7).
  3. a rough unequal pair (lambda = 2, eps_r = 1e-2, frictionless) breaks the symmetry (final
     offset > 0.6); its contact force is normal (F_t = 0) and follows Hertz with the pair's
     stiffness, |F_n| = k_n sqrt(2 R*) (h_r - g)^{3/2}, R* = lambda/(1 + lambda), g = |r| - 1 -
     lambda (1e-9 relative at every contact record), exactly while g < h_r; with mu_d = 0.3
     (run A of 2) |F_t| <= mu_d |F_n| always and = when sliding (1e-12 relative).
"""
import math
from pairtraj_lib import run_deck, interp, Checker

c = Checker()
grid = [-5.99 + 11.98 * k / 2000 for k in range(2001)]

# 1. smooth pairs
for lam in ("1.4", "2.0"):
    s, rows = run_deck("pair_eps0", tag="uneq_smooth_%s" % lam, dt_out="0.002",
                       x_end="6.0\n  size_ratio = %s" % lam)
    dy = abs(s["final_y"] - 0.5)
    c.check("lambda = %s smooth: final offset = initial 0.5 within 1e-7" % lam, dy < 1e-7,
            "(|dy| = %.2e, min gap %.3e)" % (dy, s["min_gap"]))
    xs = [r["x"] for r in rows]
    ys = [r["y"] for r in rows]
    asym = max(abs(interp(xs, ys, x) - interp(xs, ys, -x)) for x in grid)
    c.check("lambda = %s smooth: max |y(x) - y(-x)| < 1e-5" % lam, asym < 1e-5, "(%.2e)" % asym)
    th = [r["theta"] for r in rows][::-1]
    tgrid = [th[0] + 1e-6 + (math.pi - 2 * th[0] - 2e-6) * k / 2000 for k in range(2001)]
    for name in ("N1star", "N2star"):
        n = [r[name] for r in rows][::-1]
        scale = max(abs(v) for v in n)
        anti = max(abs(interp(th, n, t) + interp(th, n, math.pi - t)) for t in tgrid) / scale
        c.check("lambda = %s smooth: %s(theta) = -%s(pi - theta) within 1e-4 of max" % (lam, name, name),
                anti < 1e-4, "(%.2e, max %.4f)" % (anti, scale))

# 2. relabelling, rough and frictional
sa, ra = run_deck("pair_eps1e-2_mu03", tag="uneq_swap_a", dt_out="0.05",
                  x_end="6.0\n  size_ratio = 2.0")
sb, rb = run_deck("pair_eps1e-2_mu03", tag="uneq_swap_b", dt_out="0.05", eps_r="0.005",
                  eps_bar="0.1", start="-3.0, 0.25, 0.0", x_end="3.0\n  size_ratio = 0.5")
n = min(len(ra), len(rb)) - 1          # common output times (the last record is at x_end)
c.check("relabelling: same output times", all(abs(ra[k]["t"] - rb[k]["t"]) < 1e-12 for k in range(n)))
dpos = max(abs(ra[k][q] - 2 * rb[k][q]) for k in range(n) for q in ("x", "y", "z"))
c.check("relabelling: r_A(t) = 2 r_B(t) within 2e-6", dpos < 2e-6, "(%.2e)" % dpos)
dfin = abs(sa["final_y"] - 2 * sb["final_y"])
c.check("relabelling: final offsets %.9f = 2 x %.9f within 2e-6" % (sa["final_y"], sb["final_y"]),
        dfin < 2e-6, "(%.2e)" % dfin)
for qa, qb in (("N1star", "N1star"), ("N2star", "N2star"), ("N1star_contact", "N1star_contact"),
               ("N1star_1", "N1star_2"), ("N2star_1", "N2star_2"), ("N1star_2", "N1star_1"),
               ("omega1_z", "omega2_z"), ("omega2_z", "omega1_z")):
    dq = max(abs(ra[k][qa] - rb[k][qb]) for k in range(n))
    c.check("relabelling: %s(A) = %s(B) within 1e-5" % (qa, qb), dq < 1e-5, "(%.2e)" % dq)
dfc = max(abs(ra[k]["fc_normal"] - 4 * rb[k]["fc_normal"]) for k in range(n)) / sa["max_fc_normal"]
c.check("relabelling: |F_n|(A) = 4 |F_n|(B) within 1e-5 of max", dfc < 1e-5, "(%.2e)" % dfc)
c.check("relabelling: the runs do touch and slide",
        sum(r["contact"] for r in ra) > 5 and sum(r["sliding"] for r in ra) > 2)

# 3. rough unequal pair
lam, h_r, eps_bar = 2.0, 1e-2, 0.05
s, rows = run_deck("pair_eps1e-2", tag="uneq_rough", dt_out="0.01", x_end="6.0\n  size_ratio = 2.0")
c.check("lambda = 2, eps_r = 1e-2: fore-aft symmetry broken, final offset > 0.6", s["final_y"] > 0.6,
        "(%.6f)" % s["final_y"])
c.check("frictionless: no tangential contact force", all(r["fc_tangential"] == 0 for r in rows))
k_pair = 6 * math.pi / (eps_bar * h_r) ** 1.5 * math.sqrt(2 * lam / (1 + lam))
contact = [r for r in rows if r["contact"] == 1]
herr = max(abs(r["fc_normal"] - k_pair * (h_r - r["gap"]) ** 1.5) / r["fc_normal"] for r in contact)
c.check("Hertz with k_n sqrt(2 R*) at %d contact records within 1e-9" % len(contact), herr < 1e-9,
        "(%.2e, max |F_n| %.3f)" % (herr, s["max_fc_normal"]))
c.check("in contact exactly while gap |r| - 1 - lambda < h_r",
        all((r["gap"] < h_r) == (r["contact"] == 1) for r in rows))
cap = max(r["fc_tangential"] / r["fc_normal"] for r in ra if r["contact"] == 1)
slide = max(abs(r["fc_tangential"] - 0.3 * r["fc_normal"]) / r["fc_normal"] for r in ra if r["sliding"] == 1)
c.check("mu_d = 0.3: |F_t| <= mu_d |F_n|, equal when sliding", cap <= 0.3 * (1 + 1e-12) and slide < 1e-12,
        "(max F_t/F_n %.15f)" % cap)
c.done()
