#!/usr/bin/env bash
# One prepared command for a lent GPU: the hardware-vs-reference
# tolerance check on scenes that together run every pass and term, then the
# GPU throughput of plain WCSPH and of the PBF scenes, with per-pass times.
# Results under $OUT: compare.log, throughput_wcsph.json, throughput_pbf.json,
# summary.txt (and device_check.log, the whole output).
#
# Here, before the device call (the binary is built here and carried):
#   cargo build --release && mkdir -p .dev && cp target/release/spatter .dev/
#   (.gitignore lists /.dev/ and /.gl/: they travel only as `carry`)
#   (the Vulkan loader libvulkan.so.1, once, into .gl/: the device machine has the
#   NVIDIA driver but may lack the loader)
# The device call (run, carry [".dev", ".gl"], timeout_s 600):
#   bash tools/device_check.sh
# Rehearsal here on lavapipe, small sizes, in a couple of minutes:
#   bash tools/device_check.sh --smoke
#
# The full run is sized for 8 minutes on one H100/H200: at most 3 minutes of
# comparisons, 20 steps each (the CPU reference on the device's cores is the
# slow side; those not started by then are listed as skipped), then at most
# 2.5 + 2.5 minutes of throughput (20 timed steps a size; bench throughput skips a
# size that does not fit). First run: 2026-12-04 smoke on lavapipe, 76 s,
# 14 scenes within tolerance (bit-identical); again 2026-12-06 at 84d1652,
# 93 s on an Intel host with a benchmark beside it, the same 14.
set -uo pipefail

smoke=0
[[ "${1:-}" == "--smoke" ]] && smoke=1
OUT="${OUT:-$(mktemp -d /tmp/device_check.XXXXXX)}"
mkdir -p "$OUT"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/xdg-$$}"
mkdir -p "$XDG_RUNTIME_DIR"
exec > >(tee "$OUT/device_check.log") 2>&1

# The Vulkan loader on a bare device machine (carried as .gl/*.deb).
if [[ $smoke == 0 && -d .gl ]] && ! ldconfig -p | grep -q libvulkan; then
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
fi
if [[ $smoke == 0 && -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]]; then
    export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi

bin=.dev/spatter
[[ -x $bin ]] || bin=target/release/spatter
if [[ ! -x $bin ]]; then
    echo "device_check: no binary (.dev/spatter or target/release/spatter): build it here first"
    exit 2
fi
echo "device_check: $(date -u +%FT%TZ), binary $bin, smoke=$smoke, OUT=$OUT"
command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader

# Scenes that together run every pass and pair term, and the steps each.
# (scene, steps, extra --set arguments)
if [[ $smoke == 1 ]]; then
    steps=3
else
    steps=20
fi
compare_cases=(
    "validation/dam_break_3d.toml|dx=0.04"                        # fluid, walls, sort
    "validation/jet_outflow_2d.toml|"                             # outflow, removals
    "validation/laplace_disc_2d.toml|dx=2e-3"                     # tension with gas, interface
    "validation/laplace_free_disc_2d.toml|dx=2e-3"                # free-surface tension, delta-SPH
    "validation/sessile_drop_2d.toml|"                            # wetting
    "validation/recoil_layer_2d.toml|"                            # recoil, evaporation
    "validation/laser_flat_plate.toml|dx=2e-5"                    # Beer-Lambert bins
    "validation/melting_grain_2d.toml|"                           # rigid melting grain
    "validation/powder_bed_at_rest_2d.toml|"                      # bodies and contact
    "validation/free_rotation_3d.toml|"                           # 3D bodies
    "validation/thermocapillary_2d.toml|"                         # Marangoni
    "pbf/line_melt_coarse_2d.toml|"                               # heat, melting, laser surface, barrier
    "validation/hydrostatic_dfsph_2d.toml|"                       # DFSPH solves, implicit viscosity
    "spray/j22_fluent_case_2d.toml|dx=4e-6"                       # DFSPH with heat and the mushy sink
)
: > "$OUT/compare.log"
fails=0
skipped=0
for c in "${compare_cases[@]}"; do
    # The comparisons get 3 minutes in all; the throughput needs the rest.
    if [[ $smoke == 0 && $SECONDS -gt 180 ]]; then
        echo "== $c: skipped (the comparisons' 3 minutes are spent)" | tee -a "$OUT/compare.log"
        skipped=$((skipped + 1))
        continue
    fi
    scene=${c%%|*}
    set_arg=${c#*|}
    args=(compare "scenarios/$scene" --by-tolerance --steps "$steps")
    [[ -n $set_arg ]] && args+=(--set "$set_arg")
    echo "== $scene ($set_arg)" | tee -a "$OUT/compare.log"
    if ! timeout 60 "$bin" "${args[@]}" >>"$OUT/compare.log" 2>&1; then
        fails=$((fails + 1))
        echo "   FAILED or out of tolerance (see compare.log)"
    fi
done

# Throughput: plain WCSPH (3D dam break) and the PBF scenes, GPU only.
if [[ $smoke == 1 ]]; then
    wcsph_sizes="1e4"
    pbf_sizes="1e5"             # the powder bed's grains need a finer lattice than 1e4
    tsteps=2
else
    wcsph_sizes="1e6,1e7"
    pbf_sizes="1e6,1.7e7"
    tsteps=20
fi
timeout 150 "$bin" bench throughput --backend gpu --scenes dam_break_3d \
    --sizes "$wcsph_sizes" --steps "$tsteps" --pass-costs-at 0 \
    --json "$OUT/throughput_wcsph.json" || echo "throughput (WCSPH) ended early"
timeout 150 "$bin" bench throughput --backend gpu --scenes line_melt,powder_bed \
    --sizes "$pbf_sizes" --steps "$tsteps" --pass-costs-at 0 \
    --json "$OUT/throughput_pbf.json" || echo "throughput (PBF) ended early"

{
    echo "device_check $(date -u +%FT%TZ) smoke=$smoke"
    echo "compare --by-tolerance: ${#compare_cases[@]} scenes, $fails failed or out of tolerance, $skipped skipped for time"
    grep -E "^== |within hardware tolerance|error" "$OUT/compare.log" | paste - - | head -40
    for f in throughput_wcsph throughput_pbf; do
        [[ -f "$OUT/$f.json" ]] && echo "$f.json: $(wc -c <"$OUT/$f.json") bytes"
    done
} > "$OUT/summary.txt"
cat "$OUT/summary.txt"
[[ $fails == 0 ]]
