"""Read spatter run outputs: MCAP streams, VTK series and sweep tables.

Install (from the repository root, into any environment):
    pip install ./python
which also installs the command `spatter-read` (`python -m spatter_read` is
the same; tools/spatter_read.py runs it from a checkout).

As tables (NumPy arrays in pandas DataFrames):
    frames(path)           one DataFrame per frame (particles still in the
                           simulation), with its time in .attrs["time"]
    diagnostics(path)      /diagnostics: a row per record
    pool_series(path)      the melt pool's figures against time
    removed(path)          the particles that left: id, phase, time, side, x...
    solidification_records(path)  /solidification: every liquidus crossing
    track_slices(path)     /track: a row per slice along x
    scan_tracks(path)      /track: a row per track of a hatch (width, depth,
                           overlap with the track before, ...)
    bodies(path)           /bodies: a row per body per frame
    sweep_table(directory) a sweep's sweep.csv

Commands:
    spatter-read summary RUN.mcap             JSON: frames, particles per frame, diagnostics, time span, removals,
                                                 rigid bodies (count, bonded, molten away, left the domain at the end)
    spatter-read plot RUN.mcap OUT.png        /diagnostics against simulated time
    spatter-read export-last RUN.mcap DIR     last frame's fields as raw little-endian arrays
    spatter-read compare-vtk RUN.mcap VTKDIR  last MCAP frame against the last .vtu of the series
    spatter-read pool RUN.mcap OUT.png        melt pool against time (the largest connected region of melt:
                                                 length, width, depth, depression under the beam, volume; the
                                                 detached melt: regions and mass; peak temperature), the same
                                                 series `spatter run --pool-csv` writes as RUN.pool.csv
    spatter-read track RUN.mcap OUT.png       laser track: remelt depth and surface height along x,
                                                 and a cross-section of the last frame (2D: the x-z
                                                 plane; 3D: y-z through the track's middle)
    spatter-read section RUN.mcap OUT.png [--times T1,T2,...] [--field NAME] [--y Y]
                                                 cross-sections of the frames nearest each time (default:
                                                 the last) side by side: 2D as it is, 3D through the plane
                                                 y = Y (default the middle), the particles within Δx/2 of
                                                 it; coloured by temperature (default; phase without heat)
                                                 or any frame channel (phase, liquid_fraction, ...) or speed
    spatter-read solidification RUN.mcap OUT.png [--cet A,N,N0]
                                                 solidification map: G against R of every liquidus
                                                 crossing (/solidification) with the columnar-to-
                                                 equiaxed transition of Gaumann et al. (2001) for
                                                 CMSX-4 (A = 1.25e6 K^3.4/(m s), N = 3.4, N0 = 2e15
                                                 m^-3; --cet gives another alloy's), and the cooling
                                                 rate G R along x

As a library: read_mcap(path) -> (frames, diagnostics, info); each frame is
(time, {field: numpy array}) of the particles still in the simulation;
info["removed"] lists the particles that left (id, phase, time, side, x, y, z,
speed, mass); info["check"] the /check message (the scene's check at the end
of a completed run: kind, metric, value, tolerance, pass, figures, series; None
without); info["solidification"] the /solidification records as columns
(t, x, y, z, gradient, solidification_rate, cooling_rate, ...: numpy arrays); info["track"] is the /track message of a laser scene (None
without); info["bodies"] the /bodies messages of a scene with rigid bodies (one
per frame: time, and per body its position, orientation, velocity, angular
velocity, mass, particles, molten_fraction, bonded, left); read_vtu(path) -> {field: numpy array}.
A file whose writer was killed (no summary) is read up to its last complete chunk.
"""
import json
import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
from mcap.decoder import DecoderFactory as McapDecoderFactory
from mcap.reader import NonSeekingReader, make_reader
from mcap.records import Metadata as MetadataRecord
from mcap.stream_reader import StreamReader
from mcap_protobuf.decoder import DecoderFactory as ProtobufDecoderFactory

# foxglove.PackedElementField.NumericType -> numpy little-endian type
NUMERIC_TYPES = {1: "u1", 2: "i1", 3: "<u2", 4: "<i2", 5: "<u4", 6: "<i4", 7: "<f4", 8: "<f8"}


def pointcloud_to_arrays(msg):
    """foxglove.PointCloud -> {field name: numpy array}, one entry per point."""
    dtype = np.dtype({
        "names": [f.name for f in msg.fields],
        "formats": [NUMERIC_TYPES[f.type] for f in msg.fields],
        "offsets": [f.offset for f in msg.fields],
        "itemsize": msg.point_stride,
    })
    points = np.frombuffer(msg.data, dtype=dtype)
    return {name: np.ascontiguousarray(points[name]) for name in dtype.names}


class JsonDecoderFactory(McapDecoderFactory):
    """/diagnostics: JSON messages described by a JSON schema."""

    def decoder_for(self, message_encoding, schema):
        if message_encoding == "json":
            return json.loads
        return None


DECODERS = [ProtobufDecoderFactory(), JsonDecoderFactory()]


def is_complete(path):
    """True when the file has its summary and footer (the writer finished)."""
    with open(path, "rb") as f:
        try:
            return make_reader(f).get_summary() is not None
        except Exception:  # no footer: the writer was killed
            return False


def _messages(path):
    """Decoded messages; an unfinished file is read record by record up to the
    last complete chunk."""
    with open(path, "rb") as f:
        if is_complete(path):
            yield from make_reader(f, decoder_factories=DECODERS).iter_decoded_messages()
            return
        reader = NonSeekingReader(f, validate_crcs=False, decoder_factories=DECODERS)
        try:
            # File order: sorting by time would read to the (missing) end first.
            yield from reader.iter_decoded_messages(log_time_order=False)
        except Exception as e:  # the truncated tail; everything before it is intact
            print(f"{path}: unfinished file, read up to its last complete chunk ({e})", file=sys.stderr)


def read_mcap(path):
    frames, diagnostics, removed = [], [], []
    info = {"schemas": {}, "metadata": {}, "track": None, "check": None, "bodies": []}
    batches = []
    for schema, channel, message, decoded in _messages(path):
        info["schemas"][channel.topic] = schema.name if schema else ""
        if channel.topic == "/particles":
            frames.append((message.log_time * 1e-9, pointcloud_to_arrays(decoded)))
        elif channel.topic == "/diagnostics":
            diagnostics.append(decoded)
        elif channel.topic == "/removed":
            removed.append(decoded)
        elif channel.topic == "/track":
            info["track"] = decoded
        elif channel.topic == "/check":
            info["check"] = decoded
        elif channel.topic == "/bodies":
            info["bodies"].append(decoded)
        elif channel.topic == "/solidification":
            batches.append(decoded)
    info["removed"] = sorted(removed, key=lambda r: (r["time"], r["id"]))
    columns = [k for k in (batches[0] if batches else {}) if k != "time"]
    info["solidification"] = {k: np.concatenate([np.asarray(b[k], dtype=float) for b in batches])
                              for k in columns}
    info["complete"] = is_complete(path)
    info["metadata"] = read_metadata(path)
    return frames, diagnostics, info


def read_metadata(path):
    """{name: {key: value}} of the file's metadata records (the run's scenario,
    version and backend live in the one named "spatter")."""
    out = {}
    with open(path, "rb") as f:
        try:
            for record in StreamReader(f).records:
                if isinstance(record, MetadataRecord):
                    out[record.name] = dict(record.metadata)
        except Exception:  # unfinished file: the records before the cut are enough
            pass
    return out


def read_vtu(path):
    """A spatter .vtu (raw appended, UInt64 headers) -> {array name: numpy array}."""
    raw = Path(path).read_bytes()
    marker = raw.index(b"<AppendedData")
    start = raw.index(b"_", marker) + 1
    header = raw[:marker].decode()
    types = {"Float32": "<f4", "UInt32": "<u4", "Int64": "<i8", "UInt8": "u1"}
    arrays = {}
    for m in re.finditer(r"<DataArray ([^>]*)/>", header):
        attrs = dict(re.findall(r'(\w+)="([^"]*)"', m.group(1)))
        offset = start + int(attrs["offset"])
        size = int.from_bytes(raw[offset:offset + 8], "little")
        data = np.frombuffer(raw[offset + 8:offset + 8 + size], dtype=types[attrs["type"]])
        comps = int(attrs.get("NumberOfComponents", "1"))
        arrays[attrs.get("Name", "points")] = data.reshape(-1, comps) if comps > 1 else data
    return arrays


def read_pvd(directory):
    """[(time, .vtu path)] from particles.pvd."""
    root = ET.parse(Path(directory) / "particles.pvd").getroot()
    return [(float(d.get("timestep")), Path(directory) / d.get("file")) for d in root.iter("DataSet")]


def summary(path):
    frames, diagnostics, info = read_mcap(path)
    times = [t for t, _ in frames]
    return {
        "frames": len(frames),
        "particles_per_frame": sorted({len(a["x"]) for _, a in frames}),
        "fields": list(frames[0][1].keys()) if frames else [],
        "diagnostics": len(diagnostics),
        "time_span": [min(times), max(times)] if times else [],
        "first_diagnostics": diagnostics[0] if diagnostics else None,
        "last_diagnostics": diagnostics[-1] if diagnostics else None,
        "diagnostics_max": {k: max(d[k] for d in diagnostics)
                            for k, v in (diagnostics[0].items() if diagnostics else [])
                            if isinstance(v, (int, float))},
        "removed": len(info["removed"]),
        "removed_by_side": {side: sum(1 for r in info["removed"] if r["side"] == side)
                            for side in sorted({r["side"] for r in info["removed"]})},
        "schemas": info["schemas"],
        "track_slices": len(info["track"]["slices"]) if info["track"] else None,
        "bodies": len(info["bodies"][-1]["bodies"]) if info["bodies"] else 0,
        "bodies_bonded": sum(1 for b in info["bodies"][-1]["bodies"] if b.get("bonded"))
        if info["bodies"] else 0,
        "bodies_molten": sum(1 for b in info["bodies"][-1]["bodies"]
                             if b.get("particles") == 0 and not b.get("bonded"))
        if info["bodies"] else 0,
        "bodies_left": sum(1 for b in info["bodies"][-1]["bodies"] if b.get("left"))
        if info["bodies"] else 0,
        "complete": info["complete"],
        "has_scenario": "scenario" in info["metadata"].get("spatter", {}),
    }


def plot(path, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    _, diagnostics, _ = read_mcap(path)
    t = np.array([d["time"] for d in diagnostics])
    panels = [("kinetic_energy", "kinetic energy (J)"), ("max_speed", "max speed (m/s)"),
              ("min_density", "density (kg/m³)"), ("dt", "Δt (s)")]
    fig, axes = plt.subplots(len(panels), 1, figsize=(7, 9), sharex=True)
    for ax, (key, label) in zip(axes, panels):
        ax.plot(t, [d[key] for d in diagnostics], marker=".")
        if key == "min_density":
            ax.plot(t, [d["max_density"] for d in diagnostics], marker=".")
            ax.legend(["min", "max"])
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("simulated time (s)")
    fig.suptitle(Path(path).name)
    fig.tight_layout()
    fig.savefig(png, dpi=100)


def pool(path, png):
    """The melt pool's figures of every /diagnostics record against time."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    _, diagnostics, _ = read_mcap(path)
    rows = [d for d in diagnostics if "pool_length" in d]
    if not rows:
        raise SystemExit(f"{path}: no melt pool figures (not a heat scene)")
    t = np.array([d["time"] for d in rows]) * 1e3
    col = lambda k: np.array([d.get(k) if d.get(k) is not None else np.nan for d in rows], float)
    fig, (a, b, c) = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    for key, label in [("pool_length", "length"), ("pool_width", "width"), ("pool_depth", "depth"),
                       ("depression_depth", "depression under the beam")]:
        v = col(key)
        if np.any(np.isfinite(v) & (v != 0)):
            a.plot(t, v * 1e6, marker=".", label=label)
    a.set_ylabel("µm")
    a.legend(fontsize=8)
    a.set_title("melt pool: the largest connected region of melt")
    b.plot(t, col("detached_melt_regions"), marker=".", label="detached regions")
    b.set_ylabel("regions")
    b2 = b.twinx()
    b2.plot(t, col("detached_melt_mass"), color="tab:red", marker=".", label="detached mass")
    b2.set_ylabel("detached mass (kg)")
    b.set_title("detached melt (splashes, lone molten grains)")
    c.plot(t, col("max_temperature"), marker=".")
    c.set_ylabel("peak temperature (K)")
    c.set_xlabel("simulated time (ms)")
    for ax in (a, b, c):
        ax.grid(True, alpha=0.3)
    fig.suptitle(Path(path).name)
    fig.tight_layout()
    fig.savefig(png, dpi=100)


def track(path, png):
    """Profile of the track along x and a cross-section of the last frame."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    frames, _, info = read_mcap(path)
    tr = info["track"]
    if not tr or not tr["slices"]:
        raise SystemExit(f"{path}: no /track (not a laser scene with melting, or nothing melted)")
    s = tr["slices"]
    x = np.array([v["x"] for v in s]) * 1e6
    depth = np.array([v["depth"] for v in s]) * 1e6
    height = np.array([v["height"] for v in s]) * 1e6
    fig, (a, b) = plt.subplots(2, 1, figsize=(10, 8))
    a.axhline(0.0, color="red", lw=1, label="initial surface")
    a.step(x, height, where="mid", label="resolidified surface")
    a.step(x, -depth, where="mid", label="remelt depth (negative down)")
    if any(v["width"] > 0 for v in s):
        a.step(x, np.array([v["width"] for v in s]) * 1e6, where="mid",
               label="track width (all tracks)" if tr.get("tracks") else "track width")
    a.set_xlabel("x (µm)")
    a.set_ylabel("µm")
    a.legend(fontsize=8)
    a.grid(True, alpha=0.3)
    p = tr["pool"]
    a.set_title(f"track: peak T {p['max_temperature']:.0f} K, deepest {p['max_depth'] * 1e6:.1f} µm, "
                f"longest pool {p['max_length'] * 1e6:.0f} µm")
    t, f = frames[-1]
    three_d = np.ptp(f["z"]) > 0
    if three_d:
        mid = 0.5 * (x[0] + x[-1]) * 1e-6
        near = np.abs(f["x"] - mid) <= 0.5 * tr["dx"]
        h, v = f["y"][near], f["z"][near]
        c = f["temperature"][near] if "temperature" in f else f["phase"][near]
        b.set_xlabel(f"y (µm), slice x = {mid * 1e6:.0f} µm")
        top = s[len(s) // 2]["initial_surface"] * 1e6
        b.axhline(top, color="red", lw=1)
        # a hatch: each track's beam line and the extent of its own melt
        # (steady means) above the surface, stacked so overlaps show
        for k, ht in enumerate(tr.get("tracks", [])):
            if abs(ht["direction"][0]) < 0.99 or ht["width"] is None:
                continue  # tracks along x only: the section is a y-z plane
            d = ht["direction"][0]
            centre = (ht["line"][1] + d * (ht["centre_offset"] or 0.0)) * 1e6
            half = 0.5 * ht["width"] * 1e6
            level = top + (k + 1) * 1.5 * tr["dx"] * 1e6
            colour = f"C{k % 10}"
            b.axvline(ht["line"][1] * 1e6, color=colour, ls="--", lw=0.8)
            b.plot([centre - half, centre + half], [level, level], color=colour, lw=3)
            note = f"track {ht['track']}: {ht['width'] * 1e6:.0f} µm"
            if ht.get("overlap") is not None:
                note += f", overlap {ht['overlap']:.2f}"
            b.annotate(note, (centre + half, level), fontsize=7, color=colour,
                       xytext=(3, -3), textcoords="offset points")
    else:
        h, v = f["x"], f["y"]
        c = f["temperature"] if "temperature" in f else f["phase"]
        b.set_xlabel("x (µm)")
        b.step(x, np.array([v_["initial_surface"] for v_ in s]) * 1e6, where="mid", color="red", lw=1)
    sc = b.scatter(h * 1e6, v * 1e6, c=c, s=6, cmap="inferno")
    fig.colorbar(sc, ax=b, label="temperature (K)" if "temperature" in f else "phase")
    b.set_ylabel("up (µm)")
    b.set_aspect("equal")
    b.set_title(f"cross-section at t = {t:.4e} s (red: initial surface)")
    fig.tight_layout()
    fig.savefig(png, dpi=100)


def scenario_of(path):
    """The resolved scenario TOML the run stored (a dict; {} without)."""
    import tomllib
    text = read_metadata(path).get("spatter", {}).get("scenario", "")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        return {}


def section(path, png, times=None, field=None, at=None):
    """Cross-sections of frames as a row of panels: 2D scenes as they are (x-z),
    3D scenes through the plane y = `at` (default: the middle of the particles'
    y range), keeping the particles within half a particle spacing of it.
    Coloured by `field` (default temperature, else phase): any frame channel,
    or "speed". One panel per time (the frame nearest each; default the last)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    frames, _, _ = read_mcap(path)
    if not frames:
        raise SystemExit(f"{path}: no frames")
    scene = scenario_of(path)
    dx = scene.get("simulation", {}).get("dx")
    if times is None:
        picked = [frames[-1]]
    else:
        picked = [min(frames, key=lambda fr: abs(fr[0] - t)) for t in times]
    names = list(scene.get("phases", {}).keys())
    fig, axes = plt.subplots(1, len(picked), figsize=(4.2 * len(picked) + 1.2, 4.2), squeeze=False,
                             sharey=True)
    up = "z" if np.ptp(frames[0][1]["z"]) > 0 else "y"
    xlim = (min(f["x"].min() for _, f in picked) * 1e6, max(f["x"].max() for _, f in picked) * 1e6)
    ylim = (min(f[up].min() for _, f in picked) * 1e6, max(f[up].max() for _, f in picked) * 1e6)
    def channel(f):
        key = field or ("temperature" if "temperature" in f else "phase")
        if key == "speed":
            return key, np.sqrt(f["vx"] ** 2 + f["vy"] ** 2 + f["vz"] ** 2)
        if key in f:
            return key, f[key]
        raise SystemExit(f"{path}: no channel {key!r} (have: {', '.join(sorted(f))}, speed)")

    # One colour scale for every panel (the colour bar is drawn once).
    every = np.concatenate([channel(f)[1] for _, f in picked])
    for ax, (t, f) in zip(axes[0], picked):
        three_d = np.ptp(f["z"]) > 0
        key, values = channel(f)
        if three_d:
            y0 = at if at is not None else 0.5 * (f["y"].min() + f["y"].max())
            half = 0.5 * (dx if dx else np.median(np.diff(np.unique(f["y"]))))
            keep = np.abs(f["y"] - y0) <= half + 1e-12
            h, v, c = f["x"][keep], f["z"][keep], values[keep]
            where = f"y = {y0 * 1e6:.0f} µm"
        else:
            h, v, c = f["x"], f["y"], values
            where = "x-y plane"
        cmap = "tab10" if key == "phase" else "inferno"
        vmin, vmax = (np.min(every), np.max(every)) if every.size else (0, 1)
        if key == "phase":
            vmin, vmax = -0.5, 9.5
        sc = ax.scatter(h * 1e6, v * 1e6, c=c, s=4 if len(h) > 5000 else 8, cmap=cmap,
                        vmin=vmin, vmax=vmax, linewidths=0)
        ax.set_aspect("equal")
        ax.set_xlim(xlim[0] - 5, xlim[1] + 5)
        ax.set_ylim(ylim[0] - 5, ylim[1] + 5)
        ax.set_xlabel("x (µm)")
        ax.set_title(f"t = {t * 1e6:.1f} µs, {where}", fontsize=9)
    axes[0][0].set_ylabel("up (µm)")
    label = {"temperature": "temperature (K)", "speed": "speed (m/s)",
             "liquid_fraction": "liquid fraction"}.get(key, key)
    bar = fig.colorbar(sc, ax=axes[0].tolist(), label=label, shrink=0.85)
    if key == "phase" and names:
        bar.set_ticks(range(min(len(names), 10)))
        bar.set_ticklabels(names[:10])
    source = read_metadata(path).get("spatter", {}).get("scenario_file") or path
    fig.suptitle(Path(source).name, fontsize=10)
    fig.savefig(png, dpi=90, bbox_inches="tight")


# Gaumann, Bezencon, Canalis & Kurz, Acta Mater. 49 (2001) 1051, for CMSX-4:
# the dendrite tip undercooling dT = (a V)^(1/n) and the heterogeneous
# nucleation density N0. Hunt's limits of the equiaxed volume fraction phi:
# fully columnar below 0.0066, fully equiaxed above 0.49.
CET_CMSX4 = (1.25e6, 3.4, 2.0e15)


def cet_gradient(v, phi, a, n, n0):
    """G on the CET line at solidification rate v (m/s) for equiaxed fraction phi:
    G^n / V = a [(-4 pi N0 / (3 ln(1 - phi)))^(1/3) / (n + 1)]^n."""
    k = (-4.0 * np.pi * n0 / (3.0 * np.log(1.0 - phi))) ** (1.0 / 3.0) / (n + 1.0)
    return (a * v) ** (1.0 / n) * k


def solidification(path, png, cet=CET_CMSX4):
    """G-R map with the CET lines, and the cooling rate along x."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    _, _, info = read_mcap(path)
    s = info["solidification"]
    if not s or len(s["t"]) == 0:
        raise SystemExit(f"{path}: no /solidification records (no phase melts, or nothing froze from the liquid)")
    ok = (s["gradient"] > 0) & (s["solidification_rate"] > 0)
    g, r, t = s["gradient"][ok], s["solidification_rate"][ok], s["t"][ok]
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.8))
    sc = a.scatter(r, g, c=t * 1e3, s=6, cmap="viridis")
    fig.colorbar(sc, ax=a, label="liquidus crossing time (ms)")
    a.set_xscale("log")
    a.set_yscale("log")
    if len(r):
        v = np.logspace(np.log10(r.min()) - 1, np.log10(r.max()) + 1, 100)
        for phi, style, label in ((0.0066, "-", "columnar above"), (0.49, "--", "equiaxed below")):
            a.plot(v, cet_gradient(v, phi, *cet), "k" + style, label=f"CET, phi = {phi} ({label})")
        a.set_xlim(v[0], v[-1])
    a.set_xlabel("solidification rate R (m/s)")
    a.set_ylabel("thermal gradient G (K/m)")
    a.set_title(f"{ok.sum()} liquidus crossings; CET: a = {cet[0]:.3g}, n = {cet[1]}, N0 = {cet[2]:.3g}")
    a.legend(fontsize=8, loc="lower right")
    cool = s["cooling_rate"][ok]
    b.scatter(s["x"][ok] * 1e6, cool, s=6, c=t * 1e3, cmap="viridis")
    b.set_yscale("log")
    b.set_xlabel("x at the crossing (µm)")
    b.set_ylabel("cooling rate G R (K/s)")
    b.set_title("cooling rate along the track")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print(f"{png}: {ok.sum()} records, median G {np.median(g):.3e} K/m, R {np.median(r):.3e} m/s, "
          f"cooling {np.median(cool):.3e} K/s")


def export_last(path, directory):
    frames, _, _ = read_mcap(path)
    if not frames:
        raise SystemExit(f"{path}: no /particles frame")
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    t, arrays = frames[-1]
    for name, values in arrays.items():
        suffix = "u32" if values.dtype.kind == "u" else "f32"
        values.astype("<u4" if suffix == "u32" else "<f4").tofile(out / f"{name}.{suffix}")
    (out / "frame.json").write_text(json.dumps({"time": t, "particles": len(arrays["x"])}))


def compare_vtk(path, directory):
    frames, _, _ = read_mcap(path)
    _, last_vtu = read_pvd(directory)[-1]
    vtu = read_vtu(last_vtu)
    _, mc = frames[-1]
    points = np.stack([mc["x"], mc["y"], mc["z"]], axis=1)
    velocity = np.stack([mc["vx"], mc["vy"], mc["vz"]], axis=1)
    checks = {"positions": np.array_equal(points, vtu["points"]),
              "velocity": np.array_equal(velocity, vtu["velocity"])}
    for name in ("density", "pressure", "mass", "phase", "id"):
        checks[name] = np.array_equal(mc[name], vtu[name])
    print(json.dumps({"vtu": str(last_vtu), "particles": len(points), "equal": checks}))
    return all(checks.values())


def _df(rows):
    import pandas as pd
    return pd.DataFrame(rows)


def frames(path):
    """One DataFrame per /particles frame: a column per field (vector fields
    split into name_x, name_y, name_z), the frame's time in .attrs["time"]."""
    import pandas as pd
    out = []
    for t, fields in read_mcap(path)[0]:
        cols = {}
        for k, v in fields.items():
            v = np.asarray(v)
            if v.ndim == 2:
                for a in range(v.shape[1]):
                    cols[f"{k}_{'xyz'[a]}"] = v[:, a]
            else:
                cols[k] = v
        df = pd.DataFrame(cols)
        df.attrs["time"] = t
        out.append(df)
    return out


def diagnostics(path):
    """The /diagnostics records, one row each (scalars; lists kept as lists)."""
    return _df(read_mcap(path)[1])


POOL_COLUMNS = ["time", "pool_length", "pool_width", "pool_depth", "depression_depth",
                "pool_volume", "detached_melt_regions", "detached_melt_particles",
                "detached_melt_mass", "max_temperature"]


def pool_series(path):
    """The melt pool against time (the records that carry it): the columns of
    POOL_COLUMNS the run wrote, as `spatter run --pool-csv` does."""
    d = diagnostics(path)
    if "pool_length" not in d:
        raise ValueError(f"{path}: no melt pool figures (not a heat scene)")
    d = d[d["pool_length"].notna()]
    return d[[c for c in POOL_COLUMNS if c in d]].reset_index(drop=True)


def removed(path):
    """The particles that left the domain: id, phase, time, side, x, y, z, speed, mass."""
    return _df(read_mcap(path)[2]["removed"])


def solidification_records(path):
    """Every liquidus crossing of /solidification: t, x, y, z, gradient,
    solidification_rate, cooling_rate, ..."""
    return _df(read_mcap(path)[2]["solidification"])


def track_slices(path):
    """The /track message's slices along x (x, depth, width, height, peak
    temperature, ...), the pool's peaks in .attrs["pool"]; None without a track."""
    t = read_mcap(path)[2]["track"]
    if t is None:
        return None
    df = _df(t.get("slices", []))
    df.attrs["pool"] = t.get("pool")
    return df


def scan_tracks(path):
    """The /track message's tracks of a hatch (a [scan] of several tracks):
    a row per track (track, t_on, t_off, width, depth, centre_offset,
    overlap_width, overlap, hatch_spacing, ...); None without a track."""
    t = read_mcap(path)[2]["track"]
    if t is None:
        return None
    return _df(t.get("tracks", []))


def bodies(path):
    """/bodies: a row per body per frame (time, body index, position,
    velocity, mass, molten fraction, bonded, left, ...)."""
    rows = []
    for msg in read_mcap(path)[2]["bodies"]:
        for k, b in enumerate(msg.get("bodies", [])):
            rows.append({"time": msg.get("time"), "body": k, **b})
    return _df(rows)


def sweep_table(directory):
    """A sweep's collected sweep.csv (`spatter sweep collect DIR`)."""
    import pandas as pd
    return pd.read_csv(Path(directory) / "sweep.csv")


def cli():
    """The `spatter-read` command."""
    return main(["spatter-read"] + sys.argv[1:])


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    cmd, path = argv[1], argv[2]
    if cmd == "summary":
        print(json.dumps(summary(path)))
    elif cmd == "plot" and len(argv) == 4:
        plot(path, argv[3])
    elif cmd == "pool" and len(argv) == 4:
        pool(path, argv[3])
    elif cmd == "track" and len(argv) == 4:
        track(path, argv[3])
    elif cmd == "solidification" and len(argv) in (4, 6) and (len(argv) == 4 or argv[4] == "--cet"):
        cet = tuple(float(v) for v in argv[5].split(",")) if len(argv) == 6 else CET_CMSX4
        if len(cet) != 3:
            raise SystemExit("--cet takes A,N,N0")
        solidification(path, argv[3], cet)
    elif cmd == "section" and len(argv) >= 4:
        opts = dict(zip(argv[4::2], argv[5::2]))
        unknown = set(opts) - {"--times", "--field", "--y"}
        if unknown or len(argv[4:]) % 2:
            raise SystemExit("section takes --times T1,T2,... --field NAME --y Y (m)")
        times = [float(v) for v in opts["--times"].split(",")] if "--times" in opts else None
        section(path, argv[3], times, opts.get("--field"),
                float(opts["--y"]) if "--y" in opts else None)
    elif cmd == "export-last" and len(argv) == 4:
        export_last(path, argv[3])
    elif cmd == "compare-vtk" and len(argv) == 4:
        return 0 if compare_vtk(path, argv[3]) else 1
    else:
        print(__doc__)
        return 2
    return 0
