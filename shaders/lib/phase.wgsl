// uses: params
// What a phase is, from its row of the parameter block.

// Wall or solid: does not move, is a wall for the fluid passes.
fn is_wall(ph: u32) -> bool {
    return P.phase_a[ph].w >= KIND_WALL;
}

// A wall phase whose particles move with its velocity (phase_b.xyz).
fn wall_moves(ph: u32) -> bool {
    return ((u32(P.wall.y) >> ph) & 1u) != 0u;
}

// Carries an evolving temperature: liquid, gas or solid in a heat scene.
fn conducts(ph: u32) -> bool {
    return P.heat.z != 0.0 && P.phase_a[ph].w != KIND_WALL;
}

fn heat_flags(ph: u32) -> u32 {
    return u32(P.phase_d[ph].w);
}
