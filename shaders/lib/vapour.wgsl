// uses: params consts math
// The vapour's pressure, F22 (10): the evaporation loss (heat) and the recoil
// (surface_forces) both use it. Twin of backend::cpu::heat::vapour_pressure.

// p_v(T) = C_p exp(-C_T (1/T - 1/T_v)) of phase ph.
fn vapour_pressure(ph: u32, t: f32) -> f32 {
    return P.phases[ph].evap_pressure * pm_exp(-(P.phases[ph].evap_temperature * (c_one() / t - P.phases[ph].inv_boiling_temperature)));
}
