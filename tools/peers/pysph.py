#!/usr/bin/env python3
"""spatter against PySPH on PySPH's 3D dam break.

    python3 tools/peers/pysph.py [--install] [--until 0.05] [--dx 0.02] [--binary PATH]

Runs spatter's version of the case (scenarios/bench/dam_break_spheric.toml: the
SPHERIC Test 2 tank, water column and obstacle of PySPH's example, its spacing,
Wendland C2 kernel with h = 1.3 dx and sound speed 32.85 m/s) on the CPU, then right
after it `pysph run dam_break_3d` with the same dx and end time, with OpenMP on
both cores and no output files. Both are timed without their set-up (PySPH's
includes compiling its kernels on the first run). Prints the simulated seconds per
wall second of each and their ratio. The schemes differ (PySPH: WCSPH with Tait's
equation, Monaghan's artificial viscosity and one boundary layer; spatter: F22's
WCSPH with water's viscosity and Adami's walls), so this compares cost, not results.

--install creates the peers' environment (.venv-peers) and installs PySPH from PyPI
(it builds Cython extensions: a few minutes, and a C compiler). Not part of CI.
"""
import argparse
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

SCENE = "scenarios/bench/dam_break_spheric.toml"


def run_peer(python, until, dx):
    pysph = os.path.join(os.path.dirname(python), "pysph")
    out = os.path.join(common.VENV, "pysph-dam-break-3d")
    cmd = [pysph, "run", "dam_break_3d", "--dx", str(dx), "--tf", str(until), "--openmp",
           "--disable-output", "-d", out]
    print("PySPH:", " ".join(cmd), flush=True)
    r = subprocess.run(cmd, capture_output=True, text=True)
    text = r.stdout + r.stderr
    took = re.search(r"Run took: ([0-9.eE+-]+) secs", text)
    fluid = re.search(r"fluid: (\d+)", text)
    if r.returncode != 0 or not took:
        raise SystemExit(f"PySPH exited {r.returncode}:\n{text[-3000:]}")
    # Steps: the calls of its integrator's first stage (EPEC evaluates the
    # accelerations twice per step) in the profile PySPH writes.
    steps = "?"
    profile = os.path.join(out, "profile_info.csv")
    if os.path.exists(profile):
        for line in open(profile):
            parts = line.strip().split(",")
            if len(parts) == 5 and parts[2] == "Integrator.stage1":
                steps = parts[3]
    return float(took.group(1)), steps, int(fluid.group(1)) if fluid else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--install", action="store_true",
                    help="create .venv-peers and install PySPH into it")
    ap.add_argument("--until", type=float, default=0.05,
                    help="simulated seconds (default 0.05: about ten minutes each at dx 0.02)")
    ap.add_argument("--dx", type=float, default=0.02, help="particle spacing (default 0.02 m)")
    ap.add_argument("--binary", default=os.path.join(common.ROOT, "target", "release", "spatter"))
    a = ap.parse_args()
    python = common.ensure_venv(["pysph"], a.install)
    ours = common.run_spatter(a.binary, SCENE, a.until, [f"dx={a.dx}"])
    wall, steps, fluid = run_peer(python, a.until, a.dx)
    common.report("PySPH", ours, a.until, wall, steps, fluid)


if __name__ == "__main__":
    main()
