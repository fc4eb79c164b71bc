// uses: params
// Arithmetic literals come from the uniform block, never from the source:
// lavapipe's compiler reassociates a literal times a product (6.0 * (a * a) differs
// from the Rust twin in 10% of inputs), while a runtime value is left alone.
// Comparisons and max/min with literals are exact and stay literal.
fn c_half() -> f32 { return P.consts.half; }
fn c_quarter() -> f32 { return P.consts.quarter; }
fn c_two() -> f32 { return P.consts.two; }
fn c_one() -> f32 { return P.consts.one; }
fn c_three() -> f32 { return P.consts.three; }
fn c_six() -> f32 { return P.consts.six; }
fn c_fifteen() -> f32 { return P.consts.fifteen; }
fn c_five() -> f32 { return P.consts.five; }
fn c_thirty() -> f32 { return P.consts.thirty; }
fn c_seventy_five() -> f32 { return P.consts.seventy_five; }
fn c_one_and_half() -> f32 { return P.consts.one_and_half; }
fn c_three_quarters() -> f32 { return P.consts.three_quarters; }
fn c_nine_quarters() -> f32 { return P.consts.nine_quarters; }
fn c_four() -> f32 { return P.consts.four; }
fn c_tenth() -> f32 { return P.consts.tenth; }
fn c_jacobi_floor() -> f32 { return P.consts.jacobi_floor; }
fn c_end_slack() -> f32 { return P.consts.end_slack; }
fn c_end_steps() -> f32 { return P.consts.end_steps; }
fn c_end_stretch() -> f32 { return P.consts.end_stretch; }
