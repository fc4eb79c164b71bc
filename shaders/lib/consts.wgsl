// uses: params
// Arithmetic literals come from the uniform block, never from the source:
// lavapipe's compiler reassociates a literal times a product (6.0 * (a * a) differs
// from the Rust twin in 10% of inputs), while a runtime value is left alone.
// Comparisons and max/min with literals are exact and stay literal.
fn c_half() -> f32 { return P.consts[0].x; }
fn c_quarter() -> f32 { return P.consts[0].y; }
fn c_two() -> f32 { return P.consts[0].z; }
fn c_one() -> f32 { return P.consts[0].w; }
fn c_three() -> f32 { return P.consts[1].x; }
fn c_six() -> f32 { return P.consts[1].y; }
fn c_fifteen() -> f32 { return P.consts[1].z; }
fn c_five() -> f32 { return P.consts[1].w; }
fn c_thirty() -> f32 { return P.consts[2].x; }
fn c_seventy_five() -> f32 { return P.consts[2].y; }
fn c_one_and_half() -> f32 { return P.consts[2].z; }
fn c_three_quarters() -> f32 { return P.consts[2].w; }
fn c_nine_quarters() -> f32 { return P.consts[3].x; }
fn c_four() -> f32 { return P.consts[6].w; }
fn c_tenth() -> f32 { return P.consts[7].x; }
