#!/usr/bin/env python3
"""Surge front of a 2D dam-break run, read from its MCAP, against the experiment
points that DualSPHysics ships with its 2D validation case, measured both ways:

  tip    the furthest liquid particle + dx/2 (what `[check] dam_break_front` uses)
  gauge  DualSPHysics' measure: the furthest point of a horizontal line 0.03 a
         above the floor where the kernel-summed liquid fraction sum_j V_j W_ij
         is at least 0.5 (quintic kernel, h = dx)

    .venv/bin/python tools/dam_break_front.py RUN.mcap COLUMN_WIDTH DX

prints Z = x/a against T = t sqrt(2g/a) per frame, and the mean, RMS and largest
Z_run - Z_data over the data points the run covers (before the far wall, Z < 3.95),
in units of a, as DualSPHysics' own record of the case reports them.
"""
import sys

import numpy as np

from spatter_read import read_mcap

G = 9.81
# DualSPHysics examples/main/01_DamBreak/EXP_X-DamTipPosition_Koshizula&Oka1996.txt
# (a = 1 m): time (s), front x/a. The points coincide with Martin & Moyce's
# (1952) n^2 = 2 series as Koshizuka & Oka (1996) plot it.
DATA_T_S = [0.0920, 0.1907, 0.2663, 0.3221, 0.3681, 0.4140, 0.4466, 0.4958,
            0.5219, 0.5646, 0.5940, 0.6366, 0.6693, 0.7021, 0.7513]
DATA_Z = [1.128, 1.244, 1.464, 1.695, 1.903, 2.123, 2.365, 2.584,
          2.804, 3.034, 3.219, 3.462, 3.704, 3.900, 4.132]
GAUGE_HEIGHT = 0.03  # of a, DualSPHysics' Swl_z003 gauge in that case


def quintic_2d(r, h):
    q = r / h
    t = [np.clip(k - q, 0.0, None) ** 5 for k in (3.0, 2.0, 1.0)]
    return 7.0 / (478.0 * np.pi * h * h) * (t[0] - 6.0 * t[1] + 15.0 * t[2])


def fronts(x, y, a, dx):
    """(tip, gauge) front positions in metres of one frame's liquid particles."""
    tip = x.max() + 0.5 * dx
    z = GAUGE_HEIGHT * a
    near = np.abs(y - z) < 3.0 * dx
    xs, ys = x[near], y[near]
    line = np.arange(0.0, tip + 3.0 * dx, 0.25 * dx)
    fraction = np.array([(dx * dx * quintic_2d(np.hypot(xs - p, ys - z), dx)).sum() for p in line])
    wet = np.nonzero(fraction >= 0.5)[0]
    return tip, (line[wet[-1]] if len(wet) else np.nan)


def main(argv):
    path, a, dx = argv[1], float(argv[2]), float(argv[3])
    frames, _, _ = read_mcap(path)
    first = frames[0][1]
    inside = (first["x"] > 0) & (first["x"] < a) & (first["y"] > 0) & (first["y"] < 2 * a)
    liquid = np.bincount(first["phase"][inside]).argmax()
    scale = np.sqrt(2.0 * G / a)
    rows = []
    print("     T    tip Z  gauge Z")
    for t, f in frames:
        m = f["phase"] == liquid
        tip, gauge = fronts(f["x"][m], f["y"][m], a, dx)
        rows.append((t * scale, tip / a, gauge / a))
        print(f"{t * scale:6.3f}  {tip / a:7.3f}  {gauge / a:7.3f}")
    rows = np.array(rows)
    data_t = np.array(DATA_T_S) * np.sqrt(2.0 * G / 1.0)
    covered = [(T, z) for T, z in zip(data_t, DATA_Z) if T <= rows[-1, 0] and z < 3.95]
    for name, col in (("tip", 1), ("gauge", 2)):
        dz = np.array([np.interp(T, rows[:, 0], rows[:, col]) - z for T, z in covered])
        rel = np.array([d / z for d, (_, z) in zip(dz, covered)])
        print(f"{name}: {len(covered)} data points, Z_run - Z_data mean {dz.mean():+.3f}, "
              f"rms {np.sqrt((dz ** 2).mean()):.3f}, largest {dz.max():+.3f} (units of a); "
              f"largest relative {100 * np.abs(rel).max():.1f}%")


if __name__ == "__main__":
    main(sys.argv)
