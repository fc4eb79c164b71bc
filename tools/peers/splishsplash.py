#!/usr/bin/env python3
"""spatter against pySPlisHSPlasH on its DamBreakModel scene.

    python3 tools/peers/splishsplash.py [--install] [--until 0.3] [--binary PATH]

Runs spatter's version of the scene (scenarios/bench/dam_break_splishsplash.toml:
47^3 = 103 823 water particles of radius 0.0104 m, cubic kernel, c = 44.3 m/s) on
the CPU, then right after it pySPlisHSPlasH 2.19's WCSPH on its shipped
DamBreakModel.json changed in four places: particle radius 0.0104 m, WCSPH
(simulationMethod 0), stiffness B = rho0 c^2 / gamma = 280 357 Pa with gamma = 7 so
that its sound speed equals spatter's, and a fixed step at spatter's acoustic limit
0.25 h / c = 1.174e-4 s (the shipped scene's CFL step is 19x that: as shipped its
"water" has a sound speed of 0.6 m/s). Both are timed without their set-up (the
peer builds volume maps of its walls first). Prints the simulated seconds per wall
second of each and their ratio.

--install creates the peers' environment (.venv-peers) and installs the peer from
PyPI. The peer's wheel bundles a libGLX that must be preloaded on Debian; this
script does that. Not part of CI.
"""
import argparse
import glob
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

SCENE = "scenarios/bench/dam_break_splishsplash.toml"
DX = 0.0208        # spatter's lattice spacing = 2 x the peer's particle radius
SOUND_SPEED = 44.3  # 10 sqrt(2 g H), H = 1 m: spatter's scene
GAMMA = 7.0

# Runs inside the peer's environment: argv = until, dt, stiffness, radius.
PEER = r"""
import json, os, sys, tempfile, time
import pysplishsplash as sph
until, dt, stiffness, radius = map(float, sys.argv[1:5])
data = os.path.join(os.path.dirname(sys.executable), "data")
with open(os.path.join(data, "Scenes", "DamBreakModel.json")) as f:
    scene = json.load(f)
c = scene["Configuration"]
c.update({"particleRadius": radius, "simulationMethod": 0, "cflMethod": 0,
          "timeStepSize": dt, "stopAt": until})
scene["Materials"][0].update({"stiffness": stiffness, "exponent": 7.0})
for rb in scene["RigidBodies"]:
    rb["geometryFile"] = os.path.join(data, "models", os.path.basename(rb["geometryFile"]))
out = tempfile.mkdtemp()
path = os.path.join(out, "scene.json")
with open(path, "w") as f:
    json.dump(scene, f)
base = sph.Exec.SimulatorBase()
base.init(["peer", "--no-gui", "--no-cache", "--output-dir", out, "--stopAt", str(until), path],
          "peer")
base.initSimulation()
sim = sph.Simulation.getCurrent()
n = sum(sim.getFluidModel(i).numActiveParticles() for i in range(sim.numberOfFluidModels()))
t0 = time.perf_counter()
base.runSimulation()
wall = time.perf_counter() - t0
tm = sph.TimeManager.getCurrent()
print(json.dumps({"sim": tm.getTime(), "wall": wall, "steps": round(tm.getTime() / dt),
                  "particles": n}))
base.cleanup()
"""


def run_peer(python, until):
    libs = glob.glob(os.path.join(os.path.dirname(python), "..", "lib", "python3*",
                                  "site-packages", "pysplishsplash.libs", "libGLX-*.so*"))
    env = dict(os.environ)
    if libs:
        env["LD_PRELOAD"] = os.path.abspath(libs[0])
    dt = 0.25 * DX / SOUND_SPEED
    stiffness = 1000.0 * SOUND_SPEED**2 / GAMMA
    print(f"pySPlisHSPlasH: WCSPH, radius {DX / 2} m, stiffness {stiffness:.0f} Pa, "
          f"dt {dt:.4e} s, until {until} s", flush=True)
    r = subprocess.run([python, "-c", PEER, str(until), str(dt), str(stiffness), str(DX / 2)],
                       capture_output=True, text=True, env=env)
    last = [l for l in r.stdout.splitlines() if l.startswith("{")]
    if r.returncode != 0 or not last:
        raise SystemExit(f"the peer exited {r.returncode}:\n{r.stdout[-3000:]}{r.stderr[-3000:]}")
    return json.loads(last[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--install", action="store_true",
                    help="create .venv-peers and install pysplishsplash 2.19.0 into it")
    ap.add_argument("--until", type=float, default=0.3, help="simulated seconds (default 0.3)")
    ap.add_argument("--binary", default=os.path.join(common.ROOT, "target", "release", "spatter"))
    a = ap.parse_args()
    python = common.ensure_venv(["pysplishsplash==2.19.0"], a.install)
    ours = common.run_spatter(a.binary, SCENE, a.until)
    peer = run_peer(python, a.until)
    common.report("pySPlisHSPlasH", ours, peer["sim"], peer["wall"], peer["steps"],
                  peer["particles"])


if __name__ == "__main__":
    main()
