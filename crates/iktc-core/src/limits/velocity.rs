//! The velocity and acceleration sources, shared by both methods.

/// Upper acceleration bound from the velocity limit \[rad/s²\]: `(v_max − q̇)/Δt`.
///
/// With the constant-acceleration integrator `q̇⁺ = q̇ + Δt q̈` and the velocity is linear in
/// time inside the step, so `q̇⁺ ≤ v_max ⇔ q̈ ≤ (v_max − q̇)/Δt` is exact in discrete time
/// (paper eq. 14, second term; Del Prete, RA-L 2018). `+inf` when `v_max = +inf`.
///
/// `qd` = `q̇` \[rad/s\], `velocity_max` = `v_max` \[rad/s\], `dt` = `Δt` \[s\].
pub fn velocity_upper(qd: f64, velocity_max: f64, dt: f64) -> f64 {
    if velocity_max == f64::INFINITY {
        f64::INFINITY
    } else {
        (velocity_max - qd) / dt
    }
}

/// Lower acceleration bound from the velocity limit \[rad/s²\]: `(−v_max − q̇)/Δt`, the mirror of
/// [`velocity_upper`]. `-inf` when `v_max = +inf`.
pub fn velocity_lower(qd: f64, velocity_max: f64, dt: f64) -> f64 {
    -velocity_upper(-qd, velocity_max, dt)
}
