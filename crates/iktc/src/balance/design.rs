//! Pole placement of Section 4.3 (eqs. 32–33, corrected), continuous and discrete.
//!
//! The state feedback `u = N u_ref − K_f [θ, θ̇]ᵀ` moves the IPCJ pole pair to
//! `−ζ_d w_d ± j w_d √(1 − ζ_d²)` and, acting on the IPCJ states only, keeps the lag pole
//! `−1/τ_s` and the Padé pole `−1/T` (the full model is block-triangular). Matching the
//! coefficients of `det(sI − (A − B K_f))` gives (errata §2.2)
//! `k₁ = (m l² w_d² + m g l − K)/K`, `k₂ = (2 ζ_d w_d m l² − b)/K`; the feed-forward
//! `N = 1 + K k₁/(K − m g l)` keeps the static COM→ZMP gain (`N = 1` when `w_d = w_n`).

use nalgebra::{Complex, DMatrix, Matrix2, Matrix4, RowVector2, RowVector4, Vector2, Vector4};
use serde::Serialize;

use super::model::{invalid, FullModelParams};
use super::poly::Polynomial;
use crate::error::{Error, Result};

/// Desired IPCJ pole pair, eq. (33).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PoleSpec {
    /// Desired damping ratio `ζ_d` \[–\], in (0, 1). The paper uses 0.72.
    pub damping_ratio: f64,
    /// Desired natural frequency `w_d` \[rad/s\]; `None` keeps the open-loop `w_n`, so only
    /// damping is added and `N = 1`.
    pub natural_frequency: Option<f64>,
}

impl Default for PoleSpec {
    fn default() -> Self {
        Self {
            damping_ratio: 0.72,
            natural_frequency: None,
        }
    }
}

impl PoleSpec {
    /// Checks `0 < ζ_d < 1` and `w_d > 0` if given.
    pub fn validate(&self) -> Result<()> {
        let z = self.damping_ratio;
        if !(z.is_finite() && z > 0.0 && z < 1.0) {
            return Err(invalid("PoleSpec::damping_ratio", z, "in (0, 1)"));
        }
        if let Some(w) = self.natural_frequency {
            if !(w.is_finite() && w > 0.0) {
                return Err(invalid("PoleSpec::natural_frequency [rad/s]", w, "> 0"));
            }
        }
        Ok(())
    }
}

/// A continuous-time pole-placement design.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ContinuousDesign {
    /// State-feedback gain `K_f = [k₁, k₂]` on `[θ, θ̇]` \[–, s\].
    pub gain: [f64; 2],
    /// Feed-forward `N` on `u_ref` that keeps the static gain \[–\].
    pub feedforward: f64,
    /// Desired natural frequency used `w_d` \[rad/s\].
    pub natural_frequency: f64,
    /// Desired damping ratio used `ζ_d` \[–\].
    pub damping_ratio: f64,
    /// Designed closed-loop poles (eq. 33) `[re, im]` \[rad/s\]: IPCJ pair, `−1/τ_s`, `−1/T`.
    pub closed_loop_poles: [[f64; 2]; 4],
}

/// Continuous pole placement by the closed forms of the errata (§2.2).
pub fn place_poles(params: &FullModelParams, spec: &PoleSpec) -> Result<ContinuousDesign> {
    params.validate()?;
    spec.validate()?;
    let ip = &params.ipcj;
    let wn = ip.modal()?.natural_frequency;
    let wd = spec.natural_frequency.unwrap_or(wn);
    let zd = spec.damping_ratio;
    let (l, g, km, bm) = (
        ip.length,
        ip.gravity,
        ip.stiffness_per_mass,
        ip.damping_per_mass,
    );
    let k1 = (l * l * wd * wd + g * l - km) / km;
    let k2 = (2.0 * zd * wd * l * l - bm) / km;
    let feedforward = 1.0 + km * k1 / (km - g * l);
    let (re, im) = (-zd * wd, wd * (1.0 - zd * zd).sqrt());
    Ok(ContinuousDesign {
        gain: [k1, k2],
        feedforward,
        natural_frequency: wd,
        damping_ratio: zd,
        closed_loop_poles: [
            [re, im],
            [re, -im],
            [-1.0 / params.lag, 0.0],
            [-1.0 / params.pade, 0.0],
        ],
    })
}

/// Settings of the discrete controller design.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DiscreteSettings {
    /// Control period `Δt` \[s\]; the paper's lower body runs at 200 Hz (0.005 s).
    pub control_period: f64,
    /// The observer's continuous poles are this multiple of the closed-loop poles \[–\] (> 1).
    /// Faster observers follow pushes sooner but pass more sensor noise into the command.
    pub observer_pole_scale: f64,
}

impl Default for DiscreteSettings {
    fn default() -> Self {
        Self {
            control_period: 0.005,
            observer_pole_scale: 2.0,
        }
    }
}

impl DiscreteSettings {
    /// Checks `Δt > 0` and `observer_pole_scale > 0`.
    pub fn validate(&self) -> Result<()> {
        if !(self.control_period.is_finite() && self.control_period > 0.0) {
            return Err(invalid(
                "DiscreteSettings::control_period [s]",
                self.control_period,
                "> 0",
            ));
        }
        if !(self.observer_pole_scale.is_finite() && self.observer_pole_scale > 0.0) {
            return Err(invalid(
                "DiscreteSettings::observer_pole_scale",
                self.observer_pole_scale,
                "> 0",
            ));
        }
        Ok(())
    }
}

/// The discrete controller: ZOH model, state feedback and current-estimator observer.
///
/// Model `x⁺ = A_d x + B_d u`, `y = C x` (exact zero-order-hold discretisation of the full
/// model). Controller `u = N_d u_ref − K_d x̄`; the gain places the discrete IPCJ poles at
/// `exp(p Δt)` of the continuous design, so `eig(A_d − B_d K_d) = exp(P_des Δt)` exactly.
/// Observer (current estimator, Franklin, Powell & Workman, *Digital Control*, §8.2):
/// `x̄ = x̂ + M (y − C x̂)`, `x̂⁺ = A_d x̄ + B_d u`, `M = A_d⁻¹ L`, where `L` places
/// `eig(A_d − L C)` at `exp(s_o P_des Δt)` (`s_o` = [`DiscreteSettings::observer_pole_scale`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscreteDesign {
    /// The model it was designed for.
    pub params: FullModelParams,
    /// The continuous design it discretises.
    pub continuous: ContinuousDesign,
    /// Control period \[s\].
    pub control_period: f64,
    /// `A_d`.
    pub ad: Matrix4<f64>,
    /// `B_d`.
    pub bd: Vector4<f64>,
    /// `C`.
    pub c: RowVector4<f64>,
    /// `K_d`, zero on the lag and Padé states.
    pub gain: RowVector4<f64>,
    /// `N_d`: keeps the discrete closed loop's static gain equal to the open loop's.
    pub feedforward: f64,
    /// Predictor observer gain `L`.
    pub observer_predictor_gain: Vector4<f64>,
    /// Current-estimator gain `M = A_d⁻¹ L`.
    pub observer_gain: Vector4<f64>,
    /// Designed discrete controller poles `exp(p Δt)`, `[re, im]`.
    pub controller_poles: [[f64; 2]; 4],
    /// Designed discrete observer poles, `[re, im]`.
    pub observer_poles: [[f64; 2]; 4],
}

/// Designs the discrete controller and observer for one case.
pub fn design_discrete(
    params: &FullModelParams,
    spec: &PoleSpec,
    settings: &DiscreteSettings,
) -> Result<DiscreteDesign> {
    settings.validate()?;
    let continuous = place_poles(params, spec)?;
    let h = settings.control_period;
    let ss = params.state_space();
    let (ad, bd) = zoh(&ss.a, &ss.b, h);
    let to_c = |p: &[f64; 2]| Complex::new(p[0], p[1]);
    let zc: Vec<Complex<f64>> = continuous
        .closed_loop_poles
        .iter()
        .map(|p| (to_c(p) * h).exp())
        .collect();
    let zo: Vec<Complex<f64>> = continuous
        .closed_loop_poles
        .iter()
        .map(|p| (to_c(p) * h * settings.observer_pole_scale).exp())
        .collect();
    // Controller on the IPCJ block, via the δ-form (A_d − I)/h for conditioning.
    let a2: Matrix2<f64> = ad.fixed_view::<2, 2>(0, 0).into_owned();
    let b2: Vector2<f64> = bd.fixed_rows::<2>(0).into_owned();
    let a2d = (a2 - Matrix2::identity()) / h;
    let b2d = b2 / h;
    let delta = |z: &Complex<f64>| (z - 1.0) / h;
    let pc = Polynomial::from_roots(&[delta(&zc[0]), delta(&zc[1])]);
    let k2 = ackermann2(&a2d, &b2d, &pc)?;
    let gain = RowVector4::new(k2[0], k2[1], 0.0, 0.0);
    // Observer: dual Ackermann on (A_δᵀ, Cᵀ); L = h L_δ.
    let a4d = (ad - Matrix4::identity()) / h;
    let po = Polynomial::from_roots(&zo.iter().map(delta).collect::<Vec<_>>());
    let l_delta = observer_ackermann4(&a4d, &ss.c, &po)?;
    let l = l_delta * h;
    let m = ad.try_inverse().ok_or_else(|| singular("A_d"))? * l;
    // Static gains: y_ss/u_ref = C (I − A_d + B_d K)⁻¹ B_d N against C (I − A_d)⁻¹ B_d.
    let i4 = Matrix4::identity();
    let ol = (ss.c * (i4 - ad).try_inverse().ok_or_else(|| singular("I − A_d"))? * bd)[0];
    let cl = (ss.c
        * (i4 - ad + bd * gain)
            .try_inverse()
            .ok_or_else(|| singular("I − A_d + B_d K_d"))?
        * bd)[0];
    let feedforward = ol / cl;
    // A lag or Padé time far below Δt (an identification that ran into its bound: T = 5e-142 s
    // was seen) overflows exp(A h); the inverses above may still "succeed" on NaN entries.
    let finite = ad.iter().chain(bd.iter()).all(|x| x.is_finite())
        && gain.iter().chain(m.iter()).all(|x| x.is_finite())
        && feedforward.is_finite();
    if !finite {
        return Err(Error::InvalidSetting {
            name: "FullModelParams (τ_s, T) [s]".into(),
            value: format!("({:e}, {:e})", params.lag, params.pade),
            expected: format!(
                "times whose discrete design at Δt = {h} s is finite (the controller or observer came out NaN or infinite)"
            ),
        });
    }
    let pair = |z: &Complex<f64>| [z.re, z.im];
    Ok(DiscreteDesign {
        params: *params,
        continuous,
        control_period: h,
        ad,
        bd,
        c: ss.c,
        gain,
        feedforward,
        observer_predictor_gain: l,
        observer_gain: m,
        controller_poles: [pair(&zc[0]), pair(&zc[1]), pair(&zc[2]), pair(&zc[3])],
        observer_poles: [pair(&zo[0]), pair(&zo[1]), pair(&zo[2]), pair(&zo[3])],
    })
}

/// Exact zero-order-hold discretisation: `exp([[A, B], [0, 0]] h) = [[A_d, B_d], [0, 1]]`.
pub fn zoh(a: &Matrix4<f64>, b: &Vector4<f64>, h: f64) -> (Matrix4<f64>, Vector4<f64>) {
    let mut m = DMatrix::<f64>::zeros(5, 5);
    m.view_mut((0, 0), (4, 4)).copy_from(&(a * h));
    m.view_mut((0, 4), (4, 1)).copy_from(&(b * h));
    let e = m.exp();
    (
        e.fixed_view::<4, 4>(0, 0).into_owned(),
        e.fixed_view::<4, 1>(0, 4).into_owned(),
    )
}

/// Ackermann's formula for a 2-state single-input system: `K = [0 1] 𝒞⁻¹ φ(A)`,
/// `𝒞 = [B, A B]`, `φ` the desired characteristic polynomial.
fn ackermann2(a: &Matrix2<f64>, b: &Vector2<f64>, phi: &Polynomial) -> Result<RowVector2<f64>> {
    let ctrb = Matrix2::from_columns(&[*b, a * b]);
    let inv = ctrb
        .try_inverse()
        .ok_or_else(|| singular("controllability matrix [B, AB]"))?;
    let c = &phi.coefficients;
    let coef = |i: usize| c.get(i).copied().unwrap_or(0.0);
    let phia = a * a + a * coef(1) + Matrix2::identity() * coef(2);
    Ok(RowVector2::new(0.0, 1.0) * inv * phia)
}

/// Ackermann's formula for the observer of a 4-state single-output system:
/// `L = φ(A) 𝒪⁻¹ e₄`, `𝒪 = [C; CA; CA²; CA³]`.
fn observer_ackermann4(
    a: &Matrix4<f64>,
    c: &RowVector4<f64>,
    phi: &Polynomial,
) -> Result<Vector4<f64>> {
    let obs = Matrix4::from_rows(&[*c, c * a, c * a * a, c * a * a * a]);
    let inv = obs
        .try_inverse()
        .ok_or_else(|| singular("observability matrix [C; CA; CA²; CA³]"))?;
    let coef = |i: usize| phi.coefficients.get(i).copied().unwrap_or(0.0);
    let i4 = Matrix4::identity();
    let phia = a * a * a * a + a * a * a * coef(1) + a * a * coef(2) + a * coef(3) + i4 * coef(4);
    Ok(phia * inv * Vector4::new(0.0, 0.0, 0.0, 1.0))
}

fn singular(what: &str) -> Error {
    Error::InvalidSetting {
        name: what.to_string(),
        value: "singular".into(),
        expected: "an invertible matrix (a controllable, observable model with finite parameters)"
            .into(),
    }
}
