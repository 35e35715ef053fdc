#!/usr/bin/env python3
"""Generate src/kernels/resistance_table.F90 (module mod_resistance_table) from
input/tables/two_sphere_resistance_equal_spheres.csv, and the twin-multipole series coefficients
of the equal-sphere resistance functions (Jeffrey & Onishi 1984; Jeffrey 1992).

The generated Fortran module is committed to the repository, so the build never reads the CSV
and never runs the recurrences; re-run this script (from anywhere) whenever the CSV changes or
the series order is raised:

    /usr/bin/python3 scripts/gen_resistance_table.py [--nmax 200]

Table numbers are copied digit for digit (as text) from the CSV, so the Fortran data equal the
table exactly (no binary round trip). The series coefficients need numpy (Debian python3-numpy)
and take about a minute at nmax = 200 (the recurrences cost O(nmax^4)).

Series coefficients. For two spheres of radius ratio lambda at s = 2r/(a1 + a2), Jeffrey & Onishi
(1984, J. Fluid Mech. 139:261, eqs 3.6-3.15, 4.6-4.11, 7.3-7.5) and Jeffrey (1992, Phys. Fluids A
4:16, eqs 19-81) write each resistance function as a power series in 1/s whose coefficients
f_k(lambda) = 2^k sum_q P_{n0, k-q, q} lambda^q follow from recurrences for P, V, Q. This script
implements those recurrences (in the form corrected and completed by Townsend 2018,
arXiv:1802.08226, eqs 5-8 and 18, whose corrections matter for YH, YM and ZM) at lambda = 1 and
writes G_m = 4^-m f_m(1), so that a scalar is  sigma * sum_m G_m t^m  over the even or the odd m,
with t = 2/s = 1/(1 + xi/2) (mod_pair_resistance documents sigma and the parity of each scalar).
Checked: the first ten coefficients of every family equal doc/METHOD.md §5.2 (libstokes), and
the ZM coefficients equal libstokes' independently generated ZM.c to all printed digits.
"""
import argparse
import csv
import os
import sys
from math import comb

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CSV_PATH = os.path.join(ROOT, "input", "tables", "two_sphere_resistance_equal_spheres.csv")
OUT_PATH = os.path.join(ROOT, "src", "kernels", "resistance_table.F90")

# Column order of the scalar block; must match the index parameters of mod_pair_resistance.
SCALARS = ["XA11", "YA11", "YB11", "XC11", "YC11", "XG11", "YG11", "YH11", "XM11", "YM11", "ZM11",
           "XA12", "YA12", "YB12", "XC12", "YC12", "XG12", "YG12", "YH12", "XM12", "YM12", "ZM12"]


def fortran_real(text):
    """A CSV number as a Fortran double literal, keeping its digits."""
    t = text.strip()
    float(t)  # validate
    if "e" in t or "E" in t:
        mant, expo = t.replace("E", "e").split("e")
        if "." not in mant:
            mant += ".0"
        return f"{mant}e{int(expo)}_dp"
    if "." not in t:
        t += ".0"
    return t + "_dp"


def data_lines(values, per_line=4, indent="    "):
    out = []
    for i in range(0, len(values), per_line):
        chunk = ", ".join(values[i:i + per_line])
        sep = ", &" if i + per_line < len(values) else " &"
        out.append(f"{indent}{chunk}{sep}")
    return out


# ------------------------------------------------------------------------------------------------
# Twin-multipole recurrences (lambda = 1 enters only through f_k; the recurrences are lambda-free)
# ------------------------------------------------------------------------------------------------

# Families, in the column order of resistance_series_coef:
#   (name, recurrence type, seed index n0, seeded array, evaluated array, evaluated n, factor)
# Type A: binomial C(n+s, n) (X^A, X^G, X^M); type Y: C(n+s, n+1) (Y^A, Y^B, Y^C, Y^G, Y^H, Y^M);
# type Z: C(n+s, n+2), s >= 2 (Z^M).
SERIES_FAMILIES = [
    ("XA", "A", 1, "P", "P", 1, 1.0),
    ("YA", "Y", 1, "P", "P", 1, 1.0),
    ("YB", "Y", 1, "P", "Q", 1, 2.0),
    ("YC", "Y", 1, "Q", "Q", 1, 1.0),
    ("XG", "A", 1, "P", "P", 2, 0.75),
    ("YG", "Y", 1, "P", "P", 2, 0.75),
    ("YH", "Y", 1, "Q", "P", 2, -0.375),
    ("XM", "A", 2, "P", "P", 2, 1.0),
    ("YM", "Y", 2, "P", "P", 2, 1.0),
    ("ZM", "Z", 2, "P", "P", 2, 1.0),
]


def recurrence(nmax, kind, n0, seed):
    """P, V, Q[n, p, q] (p + q <= nmax) of the Jeffrey-Onishi / Jeffrey recurrences.

    Computed in order of increasing p + q (every right-hand side has a smaller p + q), vectorised
    over n and the summation index s. At total T only n <= nmax - T + 2 is ever referenced."""
    import numpy as np
    nn_ = nmax + 3
    P = np.zeros((nn_, nmax + 1, nmax + 1))
    V = np.zeros_like(P)
    Q = np.zeros_like(P)
    if seed == "P":
        P[n0, 0, 0] = V[n0, 0, 0] = 1.0
    else:
        Q[n0, 0, 0] = 1.0
    smin = 2 if kind == "Z" else 1
    shift = {"A": 0, "Y": 1, "Z": 2}[kind]
    binom = np.zeros((nn_, nmax + 2))
    for a in range(1, nn_):
        for b in range(smin, nmax + 2):
            binom[a, b] = float(comb(a + b, a + shift))

    def look(arr, s, i2, i3):
        ok = (i2[None, :] >= 0) & (i3[:, None] >= 0)
        return np.where(ok, arr[s[None, :], np.maximum(i2, 0)[None, :], np.maximum(i3, 0)[:, None]],
                        0.0)

    for total in range(1, nmax + 1):
        for p in range(0, total + 1):
            q = total - p
            nhi = min(nmax - total + 2, p + 2)
            if q < smin or nhi < 1:
                continue
            nv = np.arange(1, nhi + 1)
            n = nv.astype(float)[:, None]
            s = np.arange(smin, q + 1)
            sf = s.astype(float)[None, :]
            b = binom[1:nhi + 1, smin:q + 1]
            pa = look(P, s, q - s, p - nv + 1)
            pb = look(P, s, q - s, p - nv - 1)
            vc = look(V, s, q - s - 2, p - nv + 1)
            if kind == "A":
                t = (n * (2 * n + 1) * (2 * n * sf - n - sf + 2) / (2 * (n + 1) * (2 * sf - 1) * (n + sf)) * pa
                     - n * (2 * n - 1) / (2 * (n + 1)) * pb
                     - n * (4 * n**2 - 1) / (2 * (n + 1) * (2 * sf + 1)) * vc)
                P[1:nhi + 1, p, q] = np.sum(b * t, axis=1)
                V[1:nhi + 1, p, q] = (P[1:nhi + 1, p, q]
                                      - (2 * n / ((n + 1) * (2 * n + 3)))[:, 0] * np.sum(b * pb, axis=1))
                continue
            qd = look(Q, s, q - s - 1, p - nv + 1)
            qe = look(Q, s, q - s - 1, p - nv)
            pe = look(P, s, q - s, p - nv)
            if kind == "Y":
                t = ((2 * n + 1) / (2 * (n + 1)) * (3 * (n + sf) - (n * sf + 1) * (2 * n * sf - sf - n + 2))
                     / (sf * (n + sf) * (2 * sf - 1)) * pa
                     + n * (2 * n - 1) / (2 * (n + 1)) * pb
                     + n * (4 * n**2 - 1) / (2 * (n + 1) * (2 * sf + 1)) * vc
                     - 2 * (4 * n**2 - 1) / (3 * (n + 1)) * qd)
                Q[1:nhi + 1, p, q] = np.sum(b * (sf / (n + 1) * qe - 3 / (2 * n * sf * (n + 1)) * pe), axis=1)
            else:
                t = (-2 * (2 * n + 1) * (2 * n - 1) / (n + 1) * qd
                     + n * (2 * n + 1) * (2 * n - 1) / (2 * (n + 1) * (2 * sf + 1)) * vc
                     + (2 * n + 1) / (n + 1) * (n * sf * (n + sf - 2 * n * sf - 2) - 4 * (2 * n * sf - 4 * sf - 4 * n + 2))
                     / (2 * sf * (n + sf) * (2 * sf - 1)) * pa
                     + n * (2 * n - 1) / (2 * (n + 1)) * pb)
                Q[1:nhi + 1, p, q] = np.sum(b * (sf / (n + 1) * qe - 2 / (n * sf * (n + 1)) * pe), axis=1)
            P[1:nhi + 1, p, q] = np.sum(b * t, axis=1)
            V[1:nhi + 1, p, q] = (P[1:nhi + 1, p, q]
                                  + (2 * n / ((n + 1) * (2 * n + 3)))[:, 0] * np.sum(b * pb, axis=1))
    return P, V, Q


def series_coefficients(nmax):
    """{family: [G_0 .. G_nmax]} with G_m = 4^-m f_m(lambda = 1)."""
    cache = {}
    out = {}
    for name, kind, n0, seed, which, nev, fac in SERIES_FAMILIES:
        key = (kind, n0, seed)
        if key not in cache:
            cache[key] = recurrence(nmax, kind, n0, seed)
        P, _, Q = cache[key]
        arr = P if which == "P" else Q
        out[name] = [fac * 2.0**(-m) * sum(arr[nev, m - q, q] for q in range(m + 1))
                     for m in range(nmax + 1)]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--nmax", type=int, default=200, help="highest power of the series (default 200)")
    args = ap.parse_args()
    with open(CSV_PATH, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], [r for r in rows[1:] if r]
    expected = ["s_over_a"] + SCALARS + ["A_BatchelorGreen"]
    if header != expected:
        sys.exit(f"gen_resistance_table: unexpected header in {CSV_PATH}:\n{header}")
    n = len(body)
    seps = [fortran_real(r[0]) for r in body]
    if any(float(body[i + 1][0]) <= float(body[i][0]) for i in range(n - 1)):
        sys.exit("gen_resistance_table: separations must increase strictly")

    L = []
    L.append("! GENERATED FILE, do not edit by hand.")
    L.append("! Generated by scripts/gen_resistance_table.py from")
    L.append("! input/tables/two_sphere_resistance_equal_spheres.csv (see input/tables/README.md for")
    L.append("! its origin); re-run that script after changing the CSV and commit both.")
    L.append("!")
    L.append("! Jeffrey-Onishi resistance scalars of two equal spheres at tabulated separations s = r/a,")
    L.append("! normalised as in Kim & Karrila (1991) section 11.3: A x 6 pi eta a, B and G x 4 pi eta a^2,")
    L.append("! C and H x 8 pi eta a^3, M x (20/3) pi eta a^3. Column j of resistance_table_values is")
    L.append("! scalar j in the order " + ", ".join(SCALARS[:11]) + ",")
    L.append("! " + ", ".join(SCALARS[11:]) + " (the index parameters of mod_pair_resistance).")
    L.append("! resistance_table_a_bg holds Batchelor & Green's (1972) A(r) as given in the same CSV.")
    L.append("! Pure data: no PETSc, no MPI.")
    L.append("module mod_resistance_table")
    L.append("  use mod_kinds, only: dp")
    L.append("  implicit none")
    L.append("  private")
    L.append("  public :: resistance_table_size, resistance_table_scalar_count, resistance_table_sep, &")
    L.append("            resistance_table_values, resistance_table_a_bg, resistance_table_names")
    L.append("  public :: resistance_series_nmax, resistance_series_families, resistance_series_names, &")
    L.append("            resistance_series_coef")
    L.append("")
    L.append(f"  integer, parameter :: resistance_table_size = {n}")
    L.append(f"  integer, parameter :: resistance_table_scalar_count = {len(SCALARS)}")
    L.append("")
    L.append("  ! Centre-to-centre separation s = r/a of each row.")
    L.append("  real(dp), parameter :: resistance_table_sep(resistance_table_size) = [ &")
    L += data_lines(seps)
    L.append("    ]")
    L.append("")
    L.append("  ! Scalar names, in column order.")
    L.append("  character(len=4), parameter :: resistance_table_names(resistance_table_scalar_count) = [ &")
    L += data_lines([f'"{s}"' for s in SCALARS], per_line=11)
    L.append("    ]")
    L.append("")
    L.append("  ! Batchelor & Green's A(s) as tabulated (5 significant digits).")
    L.append("  real(dp), parameter :: resistance_table_a_bg(resistance_table_size) = [ &")
    L += data_lines([fortran_real(r[-1]) for r in body])
    L.append("    ]")
    L.append("")
    L.append("  ! Scalar values, row-major in the CSV; stored column by column (separation fastest).")
    L.append("  real(dp), parameter :: resistance_table_values(resistance_table_size, &")
    L.append("                                                 resistance_table_scalar_count) = reshape([ &")
    for j, name in enumerate(SCALARS):
        L.append(f"    ! {name}")
        col = [fortran_real(r[1 + j]) for r in body]
        lines = data_lines(col)
        if j < len(SCALARS) - 1:
            lines[-1] = lines[-1][:-2] + ", &"
        L += lines
    L.append("    ], [resistance_table_size, resistance_table_scalar_count])")
    L.append("")
    coef = series_coefficients(args.nmax)
    names = [f[0] for f in SERIES_FAMILIES]
    L.append("  ! Twin-multipole series (Jeffrey & Onishi 1984; Jeffrey 1992; recurrences as corrected by")
    L.append("  ! Townsend 2018): resistance_series_coef(m, j) = G_m = 4^-m f_m(lambda = 1) of family j, the")
    L.append("  ! coefficient of t^m, t = 2/s. Computed by the recurrences in scripts/gen_resistance_table.py.")
    L.append(f"  integer, parameter :: resistance_series_nmax = {args.nmax}")
    L.append(f"  integer, parameter :: resistance_series_families = {len(names)}")
    L.append("  character(len=2), parameter :: resistance_series_names(resistance_series_families) = [ &")
    L += data_lines([f'"{n}"' for n in names], per_line=10)
    L.append("    ]")
    # one parameter per family: a single array constructor of all of them would need ~670
    # continuation lines, beyond the 255 the standard allows (gfortran warns under -std=f2018)
    for name in names:
        L.append(f"  real(dp), parameter :: series_{name.lower()}(0:resistance_series_nmax) = [ &")
        col = [f"{float(v):.17e}" + "_dp" for v in coef[name]]
        col = [c.replace("e+", "e").replace("e-0", "e-").replace("e0", "e") for c in col]
        L += data_lines(col, per_line=3)
        L.append("    ]")
    L.append("  real(dp), parameter :: resistance_series_coef(0:resistance_series_nmax, &")
    L.append("                                                resistance_series_families) = reshape([ &")
    L += data_lines([f"series_{name.lower()}" for name in names], per_line=5)
    L.append("    ], [resistance_series_nmax + 1, resistance_series_families])")
    L.append("end module mod_resistance_table")
    with open(OUT_PATH, "w") as f:
        f.write("\n".join(L) + "\n")
    print(f"gen_resistance_table: wrote {OUT_PATH} ({n} separations x {len(SCALARS)} scalars, "
          f"series to t^{args.nmax})")


if __name__ == "__main__":
    main()
