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
