#!/usr/bin/python3
"""Figures 3, 4 and 5 of Gallier et al. (2014, JFM) from bin/pairtraj output, as PNG.

    scripts/plot_pair.py [--csv-dir out] [--out-dir doc/figures] [--run]

Reads out/pair_eps0.csv, out/pair_eps1e-3.csv, out/pair_eps1e-2.csv and
out/pair_eps1e-2_mu03.csv (written by `bin/pairtraj input/pair_<case>.nml`); with --run, or when
a CSV is missing, runs bin/pairtraj on the deck first. Writes
  pair_fig3_trajectories.png   relative trajectories y(x) in the shear plane (paper figure 3);
  pair_fig4_normal_stress.png  N1*, N2* against theta, eps_r = 0, 1e-3, 1e-2, mu_d = 0 (figure 4);
  pair_fig5_friction.png       N1*, N2* against theta, eps_r = 1e-2, mu_d = 0 and 0.3 (figure 5).
theta is measured from +x (the pair arrives near theta = pi and leaves near 0); theta > pi/2 is
the compression quadrant. Needs Debian's python3 with numpy and matplotlib (the shebang is
/usr/bin/python3; another python3 on PATH may lack them).
"""
import argparse
import os
import subprocess
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import _fdsusp_path  # noqa: F401,E402  (this checkout's python/ on sys.path)
from fdsusp.plots import theta_axes  # noqa: E402
from fdsusp.run import program  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CASES = [("pair_eps0", r"$\epsilon_r = 0$", "k", "-"),
         ("pair_eps1e-3", r"$\epsilon_r = 10^{-3}$", "tab:blue", "-"),
         ("pair_eps1e-2", r"$\epsilon_r = 10^{-2}$", "tab:red", "-"),
         ("pair_eps1e-2_mu03", r"$\epsilon_r = 10^{-2}$, $\mu_d = 0.3$", "tab:orange", "--")]


def load(case, csv_dir, run):
    path = os.path.join(csv_dir, case + ".csv")
    if run or not os.path.exists(path):
        deck = os.path.join(ROOT, "input", case + ".nml")
        binary = program('pairtraj')
        print("running", binary, deck)
        subprocess.run([binary, deck], check=True, cwd=ROOT, stdout=subprocess.DEVNULL)
        path = os.path.join(ROOT, "out", case + ".csv")
    return np.genfromtxt(path, delimiter=",", names=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--csv-dir", default=os.path.join(ROOT, "out"))
    ap.add_argument("--out-dir", default=os.path.join(ROOT, "doc", "figures"))
    ap.add_argument("--run", action="store_true", help="run pairtraj on the decks first")
    args = ap.parse_args()
    os.makedirs(args.out_dir, exist_ok=True)
    data = {c[0]: load(c[0], args.csv_dir, args.run) for c in CASES}

    # Figure 3: trajectories, y stretched as in the paper.
    fig, ax = plt.subplots(figsize=(7, 4))
    phi = np.linspace(0, np.pi, 200)
    ax.fill_between(2 * np.cos(phi), 0, 2 * np.sin(phi), color="0.85", label="excluded, $r < 2a$")
    for case, label, color, style in CASES:
        d = data[case]
        ax.plot(d["x"], d["y"], style, color=color, label=label)
    ax.set_xlim(-6, 6)
    ax.set_ylim(0, 2.4)
    ax.set_xlabel("$x/a$")
    ax.set_ylabel("$y/a$")
    ax.set_title("Relative trajectories, start $(-6a, 0.5a, 0)$ (cf. JFM 2014 fig. 3)")
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(os.path.join(args.out_dir, "pair_fig3_trajectories.png"), dpi=130)
    plt.close(fig)

    # Figures 4 and 5: N1*, N2* against theta.
    for name, cases, title in (
            ("pair_fig4_normal_stress.png", CASES[:3], "frictionless, three roughnesses (cf. fig. 4)"),
            ("pair_fig5_friction.png", CASES[2:], r"$\epsilon_r = 10^{-2}$, $\mu_d = 0$ and 0.3 (cf. fig. 5)")):
        fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharex=True)
        for case, label, color, style in cases:
            d = data[case]
            axes[0].plot(d["theta"], d["N1star"], style, color=color, label=label)
            axes[1].plot(d["theta"], d["N2star"], style, color=color, label=label)
        theta_axes(axes, fontsize=8)
        fig.suptitle("Pair normal stress differences, " + title, fontsize=10)
        fig.tight_layout()
        fig.savefig(os.path.join(args.out_dir, name), dpi=130)
        plt.close(fig)
    print("wrote", ", ".join(os.path.join(args.out_dir, f) for f in (
        "pair_fig3_trajectories.png", "pair_fig4_normal_stress.png", "pair_fig5_friction.png")))


if __name__ == "__main__":
    sys.exit(main())
