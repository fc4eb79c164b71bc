"""Shared by the peer scripts: the peers' virtual environment, and spatter's own run.

The peers live in their own environment (.venv-peers at the repository root, or
$SPATTER_PEERS_VENV), apart from the reader's .venv: they pin their own numpy and
Cython, and neither is needed by spatter or its tests. Nothing here runs in CI.
"""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
VENV = os.environ.get("SPATTER_PEERS_VENV", os.path.join(ROOT, ".venv-peers"))
PYTHON = os.path.join(VENV, "bin", "python")


def ensure_venv(packages, install):
    """The peers' Python; with install=True, create the environment and pip-install
    `packages` into it first."""
    if install:
        if not os.path.exists(PYTHON):
            subprocess.run([sys.executable, "-m", "venv", VENV], check=True)
        subprocess.run([PYTHON, "-m", "pip", "install", "-q", "--disable-pip-version-check",
                        *packages], check=True)
    if not os.path.exists(PYTHON):
        raise SystemExit(f"no peer environment at {VENV}: run again with --install")
    return PYTHON


def run_spatter(binary, scene, until, sets=()):
    """Run spatter on `scene` to `until` simulated seconds on the CPU; return
    (simulated seconds, wall seconds, steps, particles) from its closing lines."""
    cmd = [binary, "run", scene, "--backend", "cpu", "--until", str(until)]
    for s in sets:
        cmd += ["--set", s]
    env = dict(os.environ)
    env.setdefault("XDG_RUNTIME_DIR", "/tmp")
    print("spatter:", " ".join(cmd), flush=True)
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, env=env)
    out = r.stdout + r.stderr
    steps = re.search(r"steps: (\d+), simulated time: ([0-9.eE+-]+) s", out)
    wall = re.search(r"wall time: ([0-9.eE+-]+) s", out)
    parts = re.search(r"particles: (\d+)", out)
    if not (steps and wall and parts):
        raise SystemExit(f"spatter exited {r.returncode} without its closing lines:\n{out}")
    return float(steps.group(2)), float(wall.group(1)), int(steps.group(1)), int(parts.group(1))


def report(name, spatter_run, peer_sim, peer_wall, peer_steps, peer_particles):
    """Print both runs and the ratio of simulated seconds per wall second."""
    sim, wall, steps, particles = spatter_run
    ours = sim / wall
    theirs = peer_sim / peer_wall
    print(f"spatter: {sim:.4g} s simulated in {wall:.1f} s wall, {steps} steps, "
          f"{particles} particles: {ours:.3e} simulated s per wall s")
    print(f"{name}: {peer_sim:.4g} s simulated in {peer_wall:.1f} s wall, {peer_steps} steps, "
          f"{peer_particles} fluid particles: {theirs:.3e} simulated s per wall s")
    print(f"ratio spatter / {name}: {ours / theirs:.2f}")
