#!/usr/bin/env python3
"""NIST AM-Bench AMB2018-02 (scenarios/pbf/amb2018_02_{a,b,c}.toml): the
measured-track checks at several resolutions and with one physics switched
off at a time, collected into one CSV and a convergence plot.

  python3 tools/amb2018_02.py run --cases c --dx 4e-5,2.5e-5,2e-5 [--variant NAME]...
  python3 tools/amb2018_02.py record CASE VARIANT DX SUMMARY.json
  python3 tools/amb2018_02.py plot

`run` calls `target/release/spatter run SCENE --set dx=DX --summary ...` for each
case, Δx and variant (build it first: `cargo build --release`), skipping runs
whose summary exists, and appends each run's figures to
docs/benchmarks/amb2018_02.csv. Where Δx does not divide the domain's height,
the open top (above the plate) is raised to the next multiple; the plate and
the beam stay as the scene has them. Costs on 2 cores: case C about 2.5 min at
40 µm, 11-20 min at 25 µm, 22-50 min at 20 µm (validate prints each).

Variants (a probe, not a fit: each switches one physics off or swaps one
cited input for another cited one):
  base        the scene as it is
  nomarangoni surface_tension.temperature_coefficient = 0
  norecoil    materials.in625.evaporation.recoil = false
  notension   no [surface_tension]
  constant    laser.model = "gaussian_surface" with flat nickel's Fresnel 0.26965
  in625_rho   IN625's own DC resistivity 1.29e-6 Ohm m (Special Metals data
              sheet) through Hagen-Rubens instead of nickel's (n, k)

`plot` draws width, depth and length against Δx for each case from the CSV,
the measurements as lines with their tolerance bands, and on the length panel
Rosenthal's conduction length at each run's absorbed power (crosses), into
docs/figures/amb2018_02_convergence.png (needs .venv's matplotlib).
"""

import csv
import json
import os
import re
import subprocess
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
CSV = os.path.join(ROOT, "docs", "benchmarks", "amb2018_02.csv")
PNG = os.path.join(ROOT, "docs", "figures", "amb2018_02_convergence.png")
MEASURED = {"a": (171.0, 151.0, 659.0), "b": (133.0, 91.0, 780.0), "c": (100.0, 60.0, 754.0)}
POWER = {"a": 150.0, "b": 195.0, "c": 195.0}
# Rosenthal's trailing length at high Peclet, P_abs / (2 pi k (T_s - T_0)), with
# IN625's mean conductivity between 293 K and the solidus (20 W/(m K), the
# scenes' table) and T_s - T_0 = 1563 - 293 K: the conduction estimate of each
# run's length at the power its rays absorbed.
K_MEAN, DT_MELT = 20.0, 1563.0 - 293.0


def rosenthal_length_um(case, fraction):
    import math
    return POWER[case] * fraction / (2.0 * math.pi * K_MEAN * DT_MELT) * 1e6
FIELDS = ["case", "variant", "dx_um", "width_um", "depth_um", "length_um",
          "absorbed_fraction", "track_height_um", "peak_temperature_k", "wall_s"]


def scene_text(case, variant):
    path = os.path.join(ROOT, "scenarios", "pbf", f"amb2018_02_{case}.toml")
    text = open(path, encoding="utf-8").read()
    if variant == "notension":
        text = re.sub(r"\n\[surface_tension\].*?(?=\n\[laser\])", "\n", text, flags=re.S)
    elif variant == "constant":
        text = text.replace('model = "ray_traced"',
                            'model = "gaussian_surface"\nabsorptivity = 0.26965')
        text = re.sub(r"\nrefractive_index = .*", "", text)
    elif variant == "in625_rho":
        text = re.sub(r"\nrefractive_index = .*", "\nelectrical_resistivity = 1.29e-6", text)
        text = text.replace("\npath = ", "\nwavelength = 1.07e-6\npath = ", 1)
    return text


def sets_for(text, dx, variant):
    sets = [f"dx={dx}"]
    lo = re.search(r"\[domain\]\s*\nmin = \[([^\]]*)\]\s*\nmax = \[([^\]]*)\]", text)
    hi = [float(v) for v in lo.group(2).split(",")]
    for a, v in enumerate(hi[:-1]):
        if abs(v / dx - round(v / dx)) > 1e-6:
            raise SystemExit(f"dx = {dx} does not divide the domain's axis {a} ({v} m)")
    top = hi[-1]
    if abs(top / dx - round(top / dx)) > 1e-6:
        top = (int(top / dx) + 1) * dx
        sets.append("domain.max=[" + ", ".join(f"{v:.6e}" for v in hi[:-1] + [top]) + "]")
    if variant == "nomarangoni":
        sets.append("surface_tension.temperature_coefficient=0.0")
    elif variant == "norecoil":
        sets.append("materials.in625.evaporation.recoil=false")
    return sets


def run(cases, dxs, variants):
    exe = os.path.join(ROOT, "target", "release", "spatter")
    work = os.path.join(ROOT, "runs", "amb2018_02")
    os.makedirs(work, exist_ok=True)
    for case in cases:
        for variant in variants:
            text = scene_text(case, variant)
            scene = os.path.join(work, f"{case}_{variant}.toml")
            with open(scene, "w", encoding="utf-8") as f:
                f.write(text)
            for dx in dxs:
                tag = f"{case}_{variant}_{dx}"
                summary = os.path.join(work, tag + ".json")
                if not os.path.exists(summary):
                    cmd = [exe, "run", scene, "--summary", summary]
                    for s in sets_for(text, float(dx), variant):
                        cmd += ["--set", s]
                    print(" ".join(cmd), flush=True)
                    with open(os.path.join(work, tag + ".log"), "w") as log:
                        subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT, check=False)
                record(case, variant, float(dx), summary)


def record(case, variant, dx, summary):
    s = json.load(open(summary))
    fig = (s.get("check") or {}).get("figures", {})
    track = s.get("track") or {}
    row = {
        "case": case, "variant": variant, "dx_um": round(dx * 1e6, 3),
        "width_um": round(fig.get("width", float("nan")) * 1e6, 1),
        "depth_um": round(fig.get("depth", float("nan")) * 1e6, 1),
        "length_um": round(fig.get("length", float("nan")) * 1e6, 1),
        "absorbed_fraction": round((s.get("laser") or {}).get("absorbed_fraction", float("nan")), 4),
        "track_height_um": round(track.get("mean_height", float("nan")) * 1e6, 1),
        "peak_temperature_k": round((track.get("pool") or {}).get("max_temperature", float("nan")), 0),
        "wall_s": round(s.get("wall_s", float("nan")), 0),
    }
    rows = [r for r in read_rows()
            if not (r["case"] == case and r["variant"] == variant and float(r["dx_um"]) == row["dx_um"])]
    rows.append({k: str(v) for k, v in row.items()})
    rows.sort(key=lambda r: (r["case"], r["variant"], -float(r["dx_um"])))
    with open(CSV, "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, FIELDS)
        w.writeheader()
        w.writerows(rows)
    print(row, flush=True)


def read_rows():
    if not os.path.exists(CSV):
        return []
    with open(CSV, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def plot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = [r for r in read_rows() if r["variant"] == "base"]
    cases = sorted({r["case"] for r in rows})
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6))
    for k, (name, tol) in enumerate([("width", 0.1), ("depth", 0.1), ("length", 0.2)]):
        ax = axes[k]
        for c in cases:
            pts = sorted((float(r["dx_um"]), float(r[name + "_um"])) for r in rows if r["case"] == c)
            line, = ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", label=f"case {c.upper()}")
            m = MEASURED[c][k]
            ax.axhline(m, color=line.get_color(), ls="--", lw=1)
            ax.axhspan(m * (1 - tol), m * (1 + tol), color=line.get_color(), alpha=0.12)
            if name == "length":
                ros = sorted((float(r["dx_um"]), rosenthal_length_um(c, float(r["absorbed_fraction"])))
                             for r in rows if r["case"] == c and r["absorbed_fraction"] != "nan")
                ax.plot([p[0] for p in ros], [p[1] for p in ros], "x", color=line.get_color(), ms=8)
        ax.set_xlabel("Δx (µm)")
        ax.set_ylabel(f"{name} (µm)")
        ax.set_title(f"{name}: measured (dashed) ± {int(tol * 100)}%")
        ax.invert_xaxis()
        ax.set_ylim(bottom=0)
    axes[0].legend(fontsize=8)
    axes[2].plot([], [], "kx", label="Rosenthal at the run's absorbed power")
    axes[2].plot([], [], "ko-", label="run")
    axes[2].legend(fontsize=7, loc="center right")
    fig.tight_layout()
    fig.savefig(PNG, dpi=110)
    print(PNG)


def main():
    if len(sys.argv) < 2 or sys.argv[1] not in ("run", "plot", "record"):
        print(__doc__)
        return 2
    if sys.argv[1] == "plot":
        plot()
        return 0
    args = sys.argv[2:]
    if sys.argv[1] == "record":
        # record CASE VARIANT DX SUMMARY.json: a run made by hand
        case, variant, dx, summary = args[:4]
        record(case, variant, float(dx), summary)
        return 0
    opt = {"--cases": "c", "--dx": "4e-5,2.5e-5", "--variant": []}
    i = 0
    while i < len(args):
        if args[i] == "--variant":
            opt["--variant"].append(args[i + 1])
        elif args[i] in opt:
            opt[args[i]] = args[i + 1]
        else:
            raise SystemExit(f"unknown option {args[i]}")
        i += 2
    variants = opt["--variant"] or ["base"]
    run(opt["--cases"].split(","), opt["--dx"].split(","), variants)
    return 0


if __name__ == "__main__":
    sys.exit(main())
