//! COM generation by preview control of the ZMP on the cart-table model (Kajita et al.,
//! "Biped walking pattern generation by using preview control of zero-moment point",
//! ICRA 2003), with the optimal preview servo of Katayama et al. ("Design of an optimal
//! controller for a discrete-time system subject to previewable demand", Int. J. Control
//! 41(3), 1985).
//!
//! ## Cart-table model (Kajita 2003)
//! Per horizontal axis, the COM at constant height `z_c` with jerk input `u = d³x/dt³` held over
//! each period `Δt` is exactly discretized as
//!
//! ```text
//! x_{k+1} = A x_k + B u_k,   x_k = (x, ẋ, ẍ)ᵀ
//! A = [[1, Δt, Δt²/2], [0, 1, Δt], [0, 0, 1]],  B = (Δt³/6, Δt²/2, Δt)ᵀ
//! p_k = C x_k,  C = (1, 0, −z_c/g)                 (ZMP of the cart-table)
//! ```
//!
//! Between samples the COM follows the cubic `x(t_k + τ) = x_k + ẋ_k τ + ẍ_k τ²/2 + u_k τ³/6`,
//! so the acceleration is continuous (piecewise linear).
//!
//! ## Optimal preview servo (Katayama 1985, as used by Kajita 2003)
//! With the tracking error `e_k = p_k − p^ref_k` and increments `Δx_k = x_k − x_{k−1}`,
//! `Δu_k = u_k − u_{k−1}`, the augmented state `X_k = (e_k, Δx_kᵀ)ᵀ` obeys
//!
//! ```text
//! X_{k+1} = Ã X_k + B̃ Δu_k − Ĩ Δp^ref_{k+1}
//! Ã = [[1, C A], [0, A]],  B̃ = (C B, Bᵀ)ᵀ,  Ĩ = (1, 0, 0, 0)ᵀ
//! ```
//!
//! and the cost `J = Σ Q_e e_k² + Δx_kᵀ Q_x Δx_k + R Δu_k²` (`Q̃ = diag(Q_e, Q_x)`) is minimized,
//! with `p^ref` known `N` samples ahead and held constant beyond, by
//!
//! ```text
//! Δu_k = −G_I e_k − G_x Δx_k − Σ_{j=1}^{N} G_p(j) Δp^ref_{k+j}
//! [G_I, G_x] = (R + B̃ᵀ P̃ B̃)⁻¹ B̃ᵀ P̃ Ã
//! G_p(j)     = −(R + B̃ᵀ P̃ B̃)⁻¹ B̃ᵀ (Ã_cᵀ)^{j−1} P̃ Ĩ,   Ã_c = Ã − B̃ [G_I, G_x]
//! ```
//!
//! where `P̃` solves the DARE of `(Ã, B̃, Q̃, R)` ([`solve_dare`]). Summing the increments
//! gives Kajita's form `u_k = −G_I Σ_{i≤k} e_i − G_x x_k − Σ_j G_p(j) p^ref_{k+j}` up to a
//! constant; the incremental form used here keeps that constant exactly at the value that
//! holds a COM at rest over a constant reference (`u_{−1} = 0`, `x_{−1} = x_0`).

use nalgebra::{DMatrix, Matrix3, RowVector3, Vector3};
use serde::Serialize;

use super::dare::{solve_dare, DareSettings, DareSolution, DareStatus};
use super::settings::{check_non_negative, check_positive, invalid};
use crate::error::{check_finite, Result};

/// Largest preview horizon `N` accepted \[samples\] (500 s at 5 ms): a guard against
/// settings that would allocate gigabytes (e.g. a `dt` typed in the wrong unit).
pub const MAX_PREVIEW_SAMPLES: usize = 100_000;

/// Settings of the preview controller.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PreviewSettings {
    /// Control period `Δt` \[s\], `> 0`. Kajita 2003 uses 5 ms.
    pub dt: f64,
    /// Preview time `T_p` \[s\], `≥ dt`; the horizon is `N = round(T_p / Δt)` samples. The
    /// preview gains `G_p(j)` decay with `j` (at the defaults `G_p(N)/G_p(1) ≈ 0.008`), so a
    /// longer preview changes the pattern little but costs `O(N)` work per tick; a much
    /// shorter one makes the COM start late and the ZMP error grow. Kajita 2003 uses 1.6 s.
    pub preview_time: f64,
    /// Weight `Q_e` on the ZMP tracking error \[1/m²\], `> 0`.
    pub q_e: f64,
    /// Diagonal of the weight `Q_x` on the state increments `Δx` (position, velocity,
    /// acceleration) \[1/m², s²/m², s⁴/m²\], each `≥ 0`; zero in Kajita 2003.
    pub q_x: [f64; 3],
    /// Weight `R` on the jerk increment \[s⁶/m²\], `> 0`. Smaller tracks the ZMP more tightly
    /// with larger jerks. Kajita 2003 uses `R = 10⁻⁶ Q_e`.
    pub r: f64,
    /// COM height `z_c` above the ground \[m\], `> 0`.
    pub com_height: f64,
    /// Gravity `g` \[m/s²\], `> 0`.
    pub gravity: f64,
    /// Stopping rule of the Riccati solver.
    pub dare: DareSettings,
}

impl Default for PreviewSettings {
    fn default() -> Self {
        Self {
            dt: 0.005,
            preview_time: 1.6,
            q_e: 1.0,
            q_x: [0.0; 3],
            r: 1e-6,
            com_height: 0.8,
            gravity: 9.81,
            dare: DareSettings::default(),
        }
    }
}

impl PreviewSettings {
    /// Checks every field (see their documentation).
    pub fn validate(&self) -> Result<()> {
        check_positive("PreviewSettings::dt [s]", self.dt)?;
        check_positive("PreviewSettings::preview_time [s]", self.preview_time)?;
        if self.preview_time < self.dt {
            return Err(invalid(
                "PreviewSettings::preview_time [s]",
                self.preview_time,
                &format!(">= dt = {}", self.dt),
            ));
        }
        let n = self.preview_time / self.dt;
        if n.round() > MAX_PREVIEW_SAMPLES as f64 {
            return Err(invalid(
                "PreviewSettings::preview_time / dt [samples]",
                n,
                &format!("<= {MAX_PREVIEW_SAMPLES}"),
            ));
        }
        check_positive("PreviewSettings::q_e", self.q_e)?;
        for (i, &w) in self.q_x.iter().enumerate() {
            check_non_negative(&format!("PreviewSettings::q_x[{i}]"), w)?;
        }
        check_positive("PreviewSettings::r", self.r)?;
        check_positive("PreviewSettings::com_height [m]", self.com_height)?;
        check_positive("PreviewSettings::gravity [m/s^2]", self.gravity)?;
        self.dare.validate()?;
        Ok(())
    }

    /// The preview horizon `N = max(1, round(T_p / Δt))` \[samples\].
    pub fn horizon(&self) -> usize {
        ((self.preview_time / self.dt).round().max(1.0)) as usize
    }
}

/// The discrete cart-table model of one axis (module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CartTable {
    /// State transition `A`.
    pub a: Matrix3<f64>,
    /// Input (jerk) matrix `B`.
    pub b: Vector3<f64>,
    /// ZMP output row `C = (1, 0, −z_c/g)`.
    pub c: RowVector3<f64>,
    /// Period `Δt` \[s\].
    pub dt: f64,
}

impl CartTable {
    /// The model for period `dt` \[s\], COM height `com_height` \[m\], gravity `gravity` \[m/s²\].
    pub fn new(dt: f64, com_height: f64, gravity: f64) -> Result<Self> {
        check_positive("cart-table dt [s]", dt)?;
        check_positive("cart-table com_height [m]", com_height)?;
        check_positive("cart-table gravity [m/s^2]", gravity)?;
        Ok(Self {
            a: Matrix3::new(1.0, dt, 0.5 * dt * dt, 0.0, 1.0, dt, 0.0, 0.0, 1.0),
            b: Vector3::new(dt * dt * dt / 6.0, 0.5 * dt * dt, dt),
            c: RowVector3::new(1.0, 0.0, -com_height / gravity),
            dt,
        })
    }

    /// The ZMP `p = C x` \[m\] of state `x = (x, ẋ, ẍ)`.
    pub fn zmp(&self, x: &Vector3<f64>) -> f64 {
        (self.c * x)[0]
    }

    /// The augmented model `(Ã, B̃, Ĩ)` of the preview servo (module documentation).
    pub fn augmented(&self) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
        let ca = self.c * self.a;
        let cb = (self.c * self.b)[0];
        let mut a = DMatrix::zeros(4, 4);
        let mut b = DMatrix::zeros(4, 1);
        let mut i = DMatrix::zeros(4, 1);
        a[(0, 0)] = 1.0;
        b[(0, 0)] = cb;
        i[(0, 0)] = 1.0;
        for c in 0..3 {
            a[(0, c + 1)] = ca[c];
            b[(c + 1, 0)] = self.b[c];
            for r in 0..3 {
                a[(r + 1, c + 1)] = self.a[(r, c)];
            }
        }
        (a, b, i)
    }
}

/// The gains of the optimal preview servo for one axis (both axes share them).
#[derive(Debug, Clone, PartialEq)]
pub struct PreviewController {
    settings: PreviewSettings,
    model: CartTable,
    integral_gain: f64,
    state_gain: RowVector3<f64>,
    preview_gains: Vec<f64>,
    riccati: DareSolution,
}

impl PreviewController {
    /// Designs the controller: builds the augmented model, solves its DARE and computes the
    /// gains `G_I`, `G_x`, `G_p(1 … N)` (module documentation). Errors on invalid settings,
    /// and if the Riccati iteration does not converge (which valid settings do not cause).
    pub fn new(settings: &PreviewSettings) -> Result<Self> {
        settings.validate()?;
        let model = CartTable::new(settings.dt, settings.com_height, settings.gravity)?;
        let (at, bt, it) = model.augmented();
        let mut q = DMatrix::zeros(4, 4);
        q[(0, 0)] = settings.q_e;
        for (i, &w) in settings.q_x.iter().enumerate() {
            q[(i + 1, i + 1)] = w;
        }
        let r = DMatrix::from_element(1, 1, settings.r);
        let riccati = solve_dare(&at, &bt, &q, &r, &settings.dare)?;
        if riccati.status != DareStatus::Converged {
            return Err(invalid(
                "PreviewSettings::dare (Riccati iteration)",
                riccati.residual,
                &format!(
                    "settings for which the DARE converges within {} iterations (status {:?})",
                    settings.dare.max_iterations, riccati.status
                ),
            ));
        }
        let p = &riccati.x;
        let s = settings.r + (bt.transpose() * p * &bt)[(0, 0)];
        let k = (bt.transpose() * p * &at) / s;
        let integral_gain = k[(0, 0)];
        let state_gain = RowVector3::new(k[(0, 1)], k[(0, 2)], k[(0, 3)]);
        let ac_t = (&at - &bt * &k).transpose();
        let mut v = p * &it;
        let n = settings.horizon();
        let mut preview_gains = Vec::with_capacity(n);
        for _ in 0..n {
            preview_gains.push(-(bt.transpose() * &v)[(0, 0)] / s);
            v = &ac_t * v;
        }
        for (j, g) in preview_gains.iter().enumerate() {
            check_finite(|| format!("preview gain G_p({})", j + 1), *g)?;
        }
        Ok(Self {
            settings: *settings,
            model,
            integral_gain,
            state_gain,
            preview_gains,
            riccati,
        })
    }

    /// The settings it was designed with.
    pub fn settings(&self) -> &PreviewSettings {
        &self.settings
    }

    /// The cart-table model.
    pub fn model(&self) -> &CartTable {
        &self.model
    }

    /// Integral gain `G_I` on the ZMP error \[1/s³\] (jerk increment per metre of error).
    pub fn integral_gain(&self) -> f64 {
        self.integral_gain
    }

    /// State gain `G_x` on `(x, ẋ, ẍ)`.
    pub fn state_gain(&self) -> RowVector3<f64> {
        self.state_gain
    }

    /// Preview gains `G_p(j)`, `j = 1 … N` (index `j − 1`).
    pub fn preview_gains(&self) -> &[f64] {
        &self.preview_gains
    }

    /// The Riccati solution `P̃` of the augmented system, with its residual.
    pub fn riccati(&self) -> &DareSolution {
        &self.riccati
    }

    /// Tracks the ZMP reference `reference[k]` at `t_k = k Δt` \[m\] on one axis from a COM at
    /// rest over `reference[0]`, the reference held at its last value beyond the slice.
    /// Returns one [`CartSample`] per reference sample (the state at `t_k` and the jerk over
    /// `[t_k, t_{k+1})`). Errors on an empty or non-finite reference.
    pub fn track(&self, reference: &[f64]) -> Result<Vec<CartSample>> {
        crate::error::check_all_finite("ZMP reference [m]", reference)?;
        let Some(&first) = reference.first() else {
            return Err(crate::error::Error::InsufficientData {
                what: "preview tracking".to_string(),
                message: "empty ZMP reference (expected at least 1 sample)".to_string(),
            });
        };
        let mut axis = PreviewAxis::at_rest(first);
        let mut out = Vec::with_capacity(reference.len());
        for k in 0..reference.len() {
            let state = axis.state;
            let future = reference.get(k + 1..).unwrap_or(&[]);
            let jerk = axis.step(self, reference[k], future);
            out.push(CartSample {
                state,
                jerk,
                zmp: self.model.zmp(&state),
            });
        }
        Ok(out)
    }
}

/// The state of the cart-table at one sample and the jerk applied after it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CartSample {
    /// `(x, ẋ, ẍ)` \[m, m/s, m/s²\] at `t_k`.
    pub state: Vector3<f64>,
    /// Jerk `u_k` over `[t_k, t_{k+1})` \[m/s³\].
    pub jerk: f64,
    /// The model's ZMP `C x_k` \[m\].
    pub zmp: f64,
}

/// The running state of the preview servo on one axis; [`PreviewAxis::step`] is the per-tick,
/// allocation-free update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreviewAxis {
    /// Current cart state `x_k = (x, ẋ, ẍ)` \[m, m/s, m/s²\].
    pub state: Vector3<f64>,
    /// Previous cart state `x_{k−1}`.
    pub previous_state: Vector3<f64>,
    /// Previous jerk `u_{k−1}` \[m/s³\].
    pub previous_jerk: f64,
}

impl PreviewAxis {
    /// A COM at rest at `position` \[m\], as if it had been there forever.
    pub fn at_rest(position: f64) -> Self {
        let s = Vector3::new(position, 0.0, 0.0);
        Self {
            state: s,
            previous_state: s,
            previous_jerk: 0.0,
        }
    }

    /// One tick: with the reference `current = p^ref_k` and `future[j − 1] = p^ref_{k+j}`
    /// (held at its last value beyond its end; only the first `N` entries are read), computes
    /// `Δu_k` (module documentation), applies `u_k = u_{k−1} + Δu_k` and advances the state
    /// to `x_{k+1}`. Returns `u_k` \[m/s³\]. Allocation-free.
    pub fn step(&mut self, ctrl: &PreviewController, current: f64, future: &[f64]) -> f64 {
        let model = &ctrl.model;
        let e = model.zmp(&self.state) - current;
        let dx = self.state - self.previous_state;
        let mut du = -ctrl.integral_gain * e - (ctrl.state_gain * dx)[0];
        let mut prev = current;
        for (g, &r) in ctrl.preview_gains.iter().zip(future.iter()) {
            du -= g * (r - prev);
            prev = r;
        }
        let u = self.previous_jerk + du;
        self.previous_state = self.state;
        self.state = model.a * self.state + model.b * u;
        self.previous_jerk = u;
        u
    }
}
