// uses: params kernel grid phase
// reads: pos mass phase
// writes: rho press
// Summation density rho_i = m_i sum_j W_ij (F22 §3.3) and EOS p = c²(rho - rho0)
// (F22 (3)), clamped at 0 with the pressure floor. Twin of src/backend/cpu/density.rs.

@compute @workgroup_size(64)
fn density(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = thread_index(gid, nwg);
    if (i >= active_particles()) { return; }
    let ph = phase[i];
    if (is_wall(ph)) { return; }
    let pi = pos[i];
    let ci = cell_coord(pi);
    let zr = z_range();
    var sum = 0.0;
    #for_each_neighbor(ci, zr, j) {
        let r2 = len2(min_image(pi, pos[j]));
        if (r2 < P.kernel.support2) {
            sum = sum + kernel_w(sqrt(r2));
        }
    }
    let r = mass[i] * sum;
    rho[i] = r;
    press[i] = equation_of_state(ph, r, P.phases[ph].rho0);
}
