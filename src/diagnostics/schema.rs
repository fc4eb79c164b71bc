//! JSON schemas of the MCAP stream's JSON topics (Foxglove's plot panel reads the
//! numbers; tools/spatter_read.py decodes with them).

use crate::model::Model;
use crate::state::DT_LIMIT_NAMES;

/// JSON schema of a `/diagnostics` message (Foxglove's plot panel reads the numbers).
pub fn diagnostics_schema(m: &Model) -> serde_json::Value {
    let num = |desc: &str| serde_json::json!({"type": "number", "description": desc});
    let per_depth = if m.dim == 2 {
        " per metre of depth"
    } else {
        ""
    };
    let phases: serde_json::Map<String, serde_json::Value> = m
        .phases
        .iter()
        .map(|p| (p.name.clone(), serde_json::json!({"type": "integer"})))
        .collect();
    let phase_masses: serde_json::Map<String, serde_json::Value> = m
        .phases
        .iter()
        .map(|p| (p.name.clone(), serde_json::json!({"type": "number"})))
        .collect();
    let mut schema = serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "spatter.Diagnostics",
        "type": "object",
        "properties": {
            "time": num("simulated time, s"),
            "step": {"type": "integer", "description": "step number"},
            "dt": num("time step the next step takes, s"),
            "dt_limit": {"type": "string", "enum": DT_LIMIT_NAMES,
                         "description": "F22 (42) limit that binds dt"},
            "kinetic_energy": num(&format!("fluid kinetic energy, J{per_depth}")),
            "total_mass": num(&format!("fluid mass, kg{per_depth}")),
            "max_speed": num("largest fluid speed, m/s"),
            "min_density": num("smallest fluid density, kg/m^3"),
            "max_density": num("largest fluid density, kg/m^3"),
            "particles": {"type": "object", "properties": phases,
                          "description": "particles in the domain per phase"},
            "removed": {"type": "object", "properties": phases,
                        "description": "particles that have left the domain per phase"},
            "removed_mass": {"type": "object", "properties": phase_masses,
                             "description": format!("mass of the particles that have left the domain per phase, kg{per_depth}")},
            "wall_penetration_max_dx": num("deepest fluid penetration behind a wall face, dx"),
            "wall_penetration_count": {"type": "integer",
                                       "description": "fluid particles more than 0.5 dx behind a wall face"}
        },
        "required": ["time", "step", "dt", "dt_limit", "kinetic_energy", "total_mass",
                     "max_speed", "min_density", "max_density", "particles",
                     "removed", "removed_mass",
                     "wall_penetration_max_dx", "wall_penetration_count"]
    });
    let any_recoil = m.phases.iter().any(|p| p.recoil().is_some());
    if m.surface_tension.is_some() || (any_recoil && m.needs_interface()) {
        let area = if m.dim == 2 {
            "m per metre of depth"
        } else {
            "m^2"
        };
        schema["properties"]["surface_area"] = num(&format!(
            "liquid surface, sum of V delta over liquid particles with a normal, {area}"
        ));
        schema["properties"]["mean_curvature"] = num(
            "delta-weighted mean curvature of the liquid surface, 1/m (0 without surface tension)",
        );
        schema["properties"]["recoil_power"] = num(&format!(
            "power of the recoil pressure on the liquid, W{per_depth}"
        ));
        schema["properties"]["capillary_number"] = num(
            "largest liquid speed as eta |u| / alpha0 (spurious currents of a drop at rest; 0 without surface tension)",
        );
        schema["properties"]["interior_normals"] = num(
            "share of surface_area on liquid particles whose Shepard sum reads a full support (>= 0.95): particle disorder inside the liquid taken for surface (0 with gas)",
        );
    }
    if m.is_thermal() {
        let unit = if m.dim == 2 {
            " per metre of depth"
        } else {
            ""
        };
        let vol = if m.dim == 2 { "m^2" } else { "m^3" };
        let extra = [
            ("max_temperature", "largest temperature, K".to_string()),
            (
                "total_enthalpy",
                format!("sum of m h over conducting particles, J{unit}"),
            ),
            (
                "absorbed_laser_power",
                format!("laser power absorbed in the last step: absorptivity x beam power, or the ray-traced rays' absorbed sum, W{unit}"),
            ),
            (
                "incident_laser_power",
                format!("beam power in the last step (the ray-traced bundle's launched sum), W{unit}"),
            ),
            (
                "leaving_laser_power",
                format!("laser power not absorbed: reflected out of the domain (ray-traced), or (1 - absorptivity) x beam power, W{unit}"),
            ),
            (
                "laser_absorbed_fraction",
                "absorbed / incident laser power (the figure calorimetry measures; 0 with the beam off)".into(),
            ),
            (
                "bounce_limit_laser_power",
                format!("part of the absorbed power that rays still carried at laser.max_bounces, taken up at their last hit, W{unit}"),
            ),
            (
                "melted_volume",
                format!("liquid-fraction-weighted volume of liquid and solid, {vol}"),
            ),
            (
                "pool_depth",
                "depth of the melt pool (the largest connected region of melt) below the initial surface in scenes with a melt track, its height elsewhere, m".into(),
            ),
            ("pool_width", "melt pool extent along y (3D), m".into()),
            ("pool_length", "melt pool extent along x, m".into()),
            ("pool_volume", format!("melt pool particles x dx^dim, {vol}")),
            (
                "detached_melt_regions",
                "connected regions of melt apart from the pool (splashed droplets, lone molten grains)".into(),
            ),
            ("detached_melt_particles", "particles in them".into()),
            ("detached_melt_mass", format!("their mass, kg{unit}")),
            (
                "evaporated_power",
                format!("evaporation heat loss, W{unit}"),
            ),
            ("radiated_power", format!("radiation heat loss, W{unit}")),
        ];
        for (k, desc) in extra {
            schema["properties"][k] = num(&desc);
        }
    }
    let solvers = super::solver_names(m);
    if !solvers.is_empty() {
        let one = serde_json::json!({"type": "object", "properties": {
            "iterations": {"type": "integer", "description": "iterations in the last step"},
            "residual": num("final residual of the last step"),
            "converged": {"type": "boolean", "description": "the residual reached the tolerance (else the bound stopped it)"},
            "capped_steps": {"type": "integer", "description": "steps since the run began that ended at the bound unconverged"}
        }});
        let props: serde_json::Map<String, serde_json::Value> = solvers
            .iter()
            .map(|n| (n.to_string(), one.clone()))
            .collect();
        schema["properties"]["solvers"] = serde_json::json!({"type": "object", "properties": props,
            "description": "each iterative solve's figures in the last step before the sample"});
    }
    if crate::track::wanted(m) {
        schema["properties"]["depression_depth"] = num(
            "depth of the surface under the beam below the initial surface, m (> 0: sunk; absent while the beam is outside the domain)",
        );
    }
    schema
}

/// JSON schema of a `/bodies` message.
pub fn bodies_schema() -> serde_json::Value {
    let vec = |n: usize, desc: &str| serde_json::json!({"type": "array", "items": {"type": "number"}, "minItems": n, "maxItems": n, "description": desc});
    serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "spatter.Bodies",
        "description": "Every rigid body's motion at one frame.",
        "type": "object",
        "properties": {
            "time": {"type": "number", "description": "s"},
            "bodies": {"type": "array", "items": {
                "type": "object",
                "properties": {
                    "body": {"type": "integer", "description": "index + 1, as the frames' `body` channel"},
                    "position": vec(3, "centre of mass, world coordinates (m)"),
                    "orientation": vec(4, "unit quaternion (x, y, z, w) from the body's principal frame to world"),
                    "velocity": vec(3, "of the centre of mass (m/s)"),
                    "angular_velocity": vec(3, "world frame (rad/s)"),
                    "mass": {"type": "number", "description": "kg (kg per metre of depth in 2D)"},
                    "particles": {"type": "integer", "description": "member particles (melted ones have left)"},
                    "molten_fraction": {"type": "number", "description": "fraction of the body's initial particles that melted away"},
                    "bonded": {"type": "boolean", "description": "bonded into the substrate by melt that solidified against it (then fixed)"},
                    "left": {"type": "boolean", "description": "its centre left the domain through an open side: its particles were removed as leaving fluid is, and its motion stops where it left"}
                },
                "required": ["body", "position", "orientation", "velocity", "angular_velocity", "mass", "particles", "molten_fraction", "bonded", "left"]
            }}
        },
        "required": ["time", "bodies"]
    })
}

/// JSON schema of a `/removed` message (crate::outflow::RemovalEvent).
pub fn removal_schema() -> serde_json::Value {
    let num = |desc: &str| serde_json::json!({"type": "number", "description": desc});
    serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "spatter.Removal",
        "type": "object",
        "properties": {
            "id": {"type": "integer", "description": "particle id"},
            "phase": {"type": "string", "description": "its phase"},
            "time": num("when it left, s"),
            "side": {"type": "string", "description": "the side it left through (x_min ... z_max)"},
            "x": num("where it was at the end of that step, m"),
            "y": num("m"),
            "z": num("m"),
            "speed": num("its speed then, m/s"),
            "mass": num("kg (per metre of depth in 2D)")
        },
        "required": ["id", "phase", "time", "side", "x", "y", "z", "speed", "mass"]
    })
}

/// JSON schema of the `/check` message (crate::checks::CheckMessage): the
/// scene's check at the end of a completed run.
pub fn check_schema() -> serde_json::Value {
    serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "spatter.Check",
        "type": "object",
        "properties": {
            "kind": {"type": "string", "description": "check.kind"},
            "metric": {"type": "string", "description": "what the value measures"},
            "value": {"type": "number"},
            "tolerance": {"type": "number", "description": "the value passes at or below it"},
            "pass": {"type": "boolean"},
            "figures": {"type": "object", "additionalProperties": {"type": ["number", "null"]},
                        "description": "named figures the check measured besides its value (SI units; null: not measured)"},
            "series": {"type": ["object", "null"], "description": "observables per sample",
                       "properties": {
                           "columns": {"type": "array", "items": {"type": "string"}},
                           "rows": {"type": "array", "items": {"type": "array", "items": {"type": "number"}}}
                       }}
        },
        "required": ["kind", "metric", "value", "tolerance", "pass", "figures"]
    })
}

/// JSON schema of the `/track` message (crate::track::TrackProfile).
pub fn track_schema() -> serde_json::Value {
    let num = |desc: &str| serde_json::json!({"type": "number", "description": desc});
    serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "spatter.Track",
        "type": "object",
        "properties": {
            "dx": num("slice width along x, m"),
            "slices": {
                "type": "array",
                "description": "slices of width dx along x that the melt reached, in x order",
                "items": {
                    "type": "object",
                    "properties": {
                        "x": num("slice centre, m"),
                        "initial_surface": num("top of the condensed material at the start, m (up axis)"),
                        "depth": num("depth the melt reached below the initial surface, m"),
                        "width": num("extent of the melt along y, m (0 in 2D)"),
                        "height": num("resolidified surface minus initial surface, m (on the beam line in 3D)"),
                        "peak_temperature": num("K")
                    }
                }
            },
            "pool": {
                "type": "object",
                "description": "the melt pool's extremes over the run's samples",
                "properties": {
                    "max_temperature": num("K"),
                    "max_temperature_time": num("s"),
                    "max_depth": num("m, below the initial surface (the largest connected region of melt)"),
                    "max_depth_time": num("s"),
                    "max_length": num("extent along x of the largest connected region of melt, m"),
                    "max_width": num("extent along y, m (0 in 2D)"),
                    "max_depression": num("deepest the surface under the beam sank below the initial surface, m"),
                    "max_depression_time": num("s")
                }
            },
            "tracks": {
                "type": "array",
                "description": "a [scan] of several tracks (3D): each track's own melt, means over its steady part (a tenth of its length in from either end); empty otherwise",
                "items": {
                    "type": "object",
                    "properties": {
                        "track": {"type": "integer", "description": "1, 2, ... in scan order"},
                        "t_on": num("beam on, s"),
                        "t_off": num("beam off, s"),
                        "line": {"type": "array", "items": {"type": "number"}, "description": "where the beam starts the track (x, y), m"},
                        "direction": {"type": "array", "items": {"type": "number"}, "description": "unit vector the beam moves along"},
                        "melted_slices": {"type": "integer", "description": "slices of dx along the track its melt reached"},
                        "width": num("extent across of its melt below the initial surface, + dx, m"),
                        "depth": num("deepest its melt reached below the initial surface, m"),
                        "centre_offset": num("centre of its melt across from the beam's line (+ left of its direction), m"),
                        "overlap_width": num("width across where its melt and the previous track's meet at the same point of the plate, + dx (0 where they do not), m; null for the first"),
                        "overlap": num("overlap_width / width"),
                        "hatch_spacing": num("the scan's distance between centre lines, m")
                    }
                }
            }
        },
        "required": ["dx", "slices", "pool", "tracks"]
    })
}
