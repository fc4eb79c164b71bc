// uses: params
// What a phase is, from its row of the parameter block.

// Wall or solid: does not move, is a wall for the fluid passes.
fn is_wall(ph: u32) -> bool {
    return P.phases[ph].kind >= KIND_WALL;
}

// A wall phase whose particles move with its velocity.
fn wall_moves(ph: u32) -> bool {
    return (P.phases[ph].flags & PHASE_MOVES) != 0u;
}

// Carries an evolving temperature: liquid, gas or solid in a heat scene.
fn conducts(ph: u32) -> bool {
    return (P.sizes.flags & FLAG_HEAT) != 0u && P.phases[ph].kind != KIND_WALL;
}

fn heat_flags(ph: u32) -> u32 {
    return P.phases[ph].flags;
}

// The reference density at temperature t: the phase's density law rho0(T)
// (PHASE_DENSITY_LAW, δ-SPH thermal expansion, R18 (3.52)), else rho0. Twin of
// Params::reference_density.
fn reference_density(ph: u32, t: f32) -> f32 {
    if ((P.phases[ph].flags & PHASE_DENSITY_LAW) == 0u) {
        return P.phases[ph].rho0;
    }
    var k = 0u;
    for (var i = 1u; i < P.phases[ph].density_points; i = i + 1u) {
        if (t >= P.phases[ph].density[i / 4u].temperature[i % 4u]) {
            k = i;
        }
    }
    let c = k % 4u;
    let row = k / 4u;
    let t_k = P.phases[ph].density[row].temperature[c];
    return P.phases[ph].density[row].value[c] + P.phases[ph].density[row].slope[c] * (t - t_k);
}

// The EOS p = c²(rho - rho0) about the given reference density (the phase's,
// or δ-SPH's rho0(T)), clamped at 0 with the pressure floor. Twin of
// backend::cpu::density::equation_of_state_about.
fn equation_of_state(ph: u32, r: f32, rho0: f32) -> f32 {
    let p = P.phases[ph].c2 * (r - rho0);
    if ((P.sizes.flags & FLAG_PRESSURE_FLOOR) != 0u) {
        return max(p, 0.0);
    }
    return p;
}
