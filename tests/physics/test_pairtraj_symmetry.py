"""pairtraj: fore-aft symmetry of the smooth pair, and its breaking by roughness (issue 3).

Invariants (Batchelor & Green 1972; doc/METHOD.md §9.4):
  1. smooth pair: the trajectory is symmetric about x = 0, y(x) = y(-x), for x in [-6, 6];
     tolerance 1e-5: output every 0.002 strain (cubic Hermite dense output) and linear
     interpolation in x (spacing dx <= 0.012) give an interpolation error (dx)^2 |y''|/8 of a
     few 1e-7 (measured total 5e-7); the integrator error is ~1e-8. A broken symmetry (e.g. a
     one-sided contact force) shows up at the 1e-2 level.
  2. smooth pair: N1* and N2* are antisymmetric about theta = pi/2 along the trajectory,
     N(theta) = -N(pi - theta) (the pair retraces its approach in the mirror quadrant and the
     stresslet changes sign with sin(2 theta)); tolerance 1e-4 of max |N|, interpolation in theta.
  3. the rough pair (eps_r = 1e-2) is NOT fore-aft symmetric: max |y(x) - y(-x)| > 0.1 (the
     offset grows from 0.5 to ~1.05); checks that test 1 can detect asymmetry.
"""
import math
from pairtraj_lib import run_deck, interp, Checker

c = Checker()
_, rows = run_deck("pair_eps0", tag="sym_eps0", dt_out="0.002")
xs = [r["x"] for r in rows]
ys = [r["y"] for r in rows]
c.check("x increases monotonically along the smooth trajectory",
        all(b > a for a, b in zip(xs, xs[1:])))
grid = [-5.99 + 11.98 * k / 2000 for k in range(2001)]
asym = max(abs(interp(xs, ys, x) - interp(xs, ys, -x)) for x in grid)
c.check("smooth: max |y(x) - y(-x)| < 1e-5", asym < 1e-5, "(%.2e)" % asym)

th = [r["theta"] for r in rows][::-1]   # increasing theta
n1 = [r["N1star"] for r in rows][::-1]
n2 = [r["N2star"] for r in rows][::-1]
tgrid = [th[0] + 1e-6 + (math.pi - 2 * th[0] - 2e-6) * k / 2000 for k in range(2001)]
for name, n in (("N1*", n1), ("N2*", n2)):
    scale = max(abs(v) for v in n)
    anti = max(abs(interp(th, n, t) + interp(th, n, math.pi - t)) for t in tgrid) / scale
    c.check("smooth: %s(theta) = -%s(pi - theta) within 1e-4 of max|%s|" % (name, name, name),
            anti < 1e-4, "(%.2e, max |%s| = %.4f)" % (anti, name, scale))

_, rows = run_deck("pair_eps1e-2", tag="sym_eps1e-2", dt_out="0.002")
xs = [r["x"] for r in rows]
ys = [r["y"] for r in rows]
asym = max(abs(interp(xs, ys, x) - interp(xs, ys, -x)) for x in grid)
c.check("rough eps_r = 1e-2: fore-aft asymmetric, max |y(x) - y(-x)| > 0.1", asym > 0.1,
        "(%.3f)" % asym)
c.done()
