//! The inverted pendulum with a compliant joint (IPCJ), Section 4.1, as corrected by the errata
//! (§1, eqs. 27, 28, 31, 32), and its full identification model with the sensor lag and the Padé
//! term (eq. 31).
//!
//! Equation of motion (26): `m l² θ̈ + b θ̇ − m g l θ = −K (θ − u)`, with ZMP output (28)
//! `y = (K/(m g)) θ + (b/(m g)) θ̇ − (K/(m g)) u`. Dividing by `m` shows that only `l`, `K/m`
//! and `b/m` enter the model; the mass is neither identifiable from ZMP data nor needed.

use nalgebra::{Complex, Matrix2, Matrix4, RowVector2, RowVector4, Vector2, Vector4};
use serde::{Deserialize, Serialize};

use super::poly::Polynomial;
use crate::error::{check_finite, Error, Result};

/// Standard gravity \[m/s²\], the default of [`IpcjParams::gravity`].
pub const STANDARD_GRAVITY: f64 = 9.81;

/// Physical parameters of one IPCJ (eq. 26), per unit mass.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IpcjParams {
    /// Pendulum length `l` \[m\]: from the compliant joint (ankle) to the centre of mass.
    pub length: f64,
    /// Joint stiffness per unit mass `K/m` \[N·m/(rad·kg)\] = \[m²/(s²·rad)\].
    pub stiffness_per_mass: f64,
    /// Joint damping per unit mass `b/m` \[N·m·s/(rad·kg)\] = \[m²/(s·rad)\].
    pub damping_per_mass: f64,
    /// Gravity `g` \[m/s²\].
    pub gravity: f64,
}

/// Natural frequency and damping ratio of the IPCJ pole pair (errata eq. 32).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Modal {
    /// `w_n = √(K/(m l²) − g/l)` \[rad/s\].
    pub natural_frequency: f64,
    /// `ζ = b / (2 w_n m l²)` \[–\].
    pub damping_ratio: f64,
}

impl IpcjParams {
    /// Parameters from the pendulum length `l` \[m\], the open-loop natural frequency `w_n`
    /// \[rad/s\] and damping ratio `ζ` \[–\] of the pole pair (inverse of errata eq. 32):
    /// `K/m = l² (w_n² + g/l)`, `b/m = 2 ζ w_n l²`.
    pub fn from_modal(
        length: f64,
        natural_frequency: f64,
        damping_ratio: f64,
        gravity: f64,
    ) -> Result<Self> {
        let p = Self {
            length,
            stiffness_per_mass: length * length * (natural_frequency.powi(2) + gravity / length),
            damping_per_mass: 2.0 * damping_ratio * natural_frequency * length * length,
            gravity,
        };
        p.validate()?;
        Ok(p)
    }

    /// Checks that every parameter is finite and positive (`b/m` may be zero).
    pub fn validate(&self) -> Result<()> {
        positive("IpcjParams::length [m]", self.length)?;
        positive(
            "IpcjParams::stiffness_per_mass [m²/(s²·rad)]",
            self.stiffness_per_mass,
        )?;
        positive("IpcjParams::gravity [m/s²]", self.gravity)?;
        check_finite(
            || "IpcjParams::damping_per_mass".into(),
            self.damping_per_mass,
        )?;
        if self.damping_per_mass < 0.0 {
            return Err(invalid(
                "IpcjParams::damping_per_mass [m²/(s·rad)]",
                self.damping_per_mass,
                ">= 0",
            ));
        }
        Ok(())
    }

    /// `K/(m l²)` \[1/s²\].
    pub fn stiffness_term(&self) -> f64 {
        self.stiffness_per_mass / (self.length * self.length)
    }

    /// `b/(m l²)` \[1/s\].
    pub fn damping_term(&self) -> f64 {
        self.damping_per_mass / (self.length * self.length)
    }

    /// Natural frequency and damping ratio of the pole pair (errata eq. 32). An error if the
    /// joint is too soft to hold the pendulum up (`K/m ≤ g l`), when `w_n` is not real.
    pub fn modal(&self) -> Result<Modal> {
        let wn2 = self.stiffness_term() - self.gravity / self.length;
        if wn2.is_nan() || wn2 <= 0.0 {
            return Err(invalid(
                "IpcjParams::stiffness_per_mass [m²/(s²·rad)]",
                self.stiffness_per_mass,
                &format!(
                    "> g·l = {} (a stiffer joint than gravity)",
                    self.gravity * self.length
                ),
            ));
        }
        let wn = wn2.sqrt();
        Ok(Modal {
            natural_frequency: wn,
            damping_ratio: self.damping_term() / (2.0 * wn),
        })
    }

    /// State space of the corrected eqs. (27)–(28), state `[θ, θ̇]` \[rad, rad/s\], input `u`
    /// \[rad\], output ZMP `y` \[m\]:
    /// `A = [[0, 1], [g/l − K/(m l²), −b/(m l²)]]`, `B = [0, K/(m l²)]ᵀ`,
    /// `C = [K/(m g), b/(m g)]`, `D = −K/(m g)`.
    pub fn state_space(&self) -> StateSpace2 {
        let (g, l) = (self.gravity, self.length);
        StateSpace2 {
            a: Matrix2::new(
                0.0,
                1.0,
                g / l - self.stiffness_term(),
                -self.damping_term(),
            ),
            b: Vector2::new(0.0, self.stiffness_term()),
            c: RowVector2::new(self.stiffness_per_mass / g, self.damping_per_mass / g),
            d: -self.stiffness_per_mass / g,
        }
    }

    /// Transfer function `y/u = −(K/(m g)) (s² − g/l) / (s² + (b/(m l²)) s + K/(m l²) − g/l)`
    /// (eq. 31 without lag and delay, corrected).
    pub fn transfer_function(&self) -> TransferFunction {
        let (g, l) = (self.gravity, self.length);
        let k = self.stiffness_per_mass / g;
        TransferFunction {
            numerator: Polynomial::new(&[-k, 0.0, k * g / l]),
            denominator: Polynomial::new(&[
                1.0,
                self.damping_term(),
                self.stiffness_term() - g / l,
            ]),
        }
    }

    /// The two poles \[rad/s\], roots of `s² + (b/(m l²)) s + K/(m l²) − g/l`, the one with the
    /// non-negative imaginary part first.
    pub fn poles(&self) -> [Complex<f64>; 2] {
        let half = 0.5 * self.damping_term();
        let disc = half * half - (self.stiffness_term() - self.gravity / self.length);
        if disc >= 0.0 {
            [
                Complex::new(-half + disc.sqrt(), 0.0),
                Complex::new(-half - disc.sqrt(), 0.0),
            ]
        } else {
            [
                Complex::new(-half, (-disc).sqrt()),
                Complex::new(-half, -(-disc).sqrt()),
            ]
        }
    }

    /// The two zeros `±√(g/l)` \[rad/s\]; the positive one makes the plant non-minimum phase.
    pub fn zeros(&self) -> [f64; 2] {
        let z = (self.gravity / self.length).sqrt();
        [z, -z]
    }

    /// Static gain `y/u` at `s = 0`: `K l / (K − m g l)` \[m/rad\].
    pub fn dc_gain(&self) -> f64 {
        let km = self.stiffness_per_mass;
        km * self.length / (km - self.gravity * self.length)
    }

    /// Frequency response `y/u (jω)` at the angular frequency `omega` \[rad/s\] \[m/rad\].
    pub fn frequency_response(&self, omega: f64) -> Complex<f64> {
        self.transfer_function().eval(Complex::new(0.0, omega))
    }
}

/// The full model of eq. (31): the IPCJ, a first-order lag `1/(τ_s s + 1)` for the unmodelled
/// dynamics and the first-order Padé term `(−s + 1/T)/(s + 1/T)`.
///
/// The Padé term with pole `−1/T` approximates a pure delay of `2T` (errata §1): the paper
/// calls `T` "the time delay"; we keep its form because its pole `−1/T` is kept in eq. (33).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FullModelParams {
    /// The pendulum with compliant joint.
    pub ipcj: IpcjParams,
    /// Time constant `τ_s` of the lag \[s\].
    pub lag: f64,
    /// Padé parameter `T` \[s\]; the delay it approximates is `2T`.
    pub pade: f64,
}

impl FullModelParams {
    /// Checks the IPCJ parameters and that `τ_s` and `T` are finite and positive.
    pub fn validate(&self) -> Result<()> {
        self.ipcj.validate()?;
        positive("FullModelParams::lag τ_s [s]", self.lag)?;
        positive("FullModelParams::pade T [s]", self.pade)
    }

    /// Four-state realisation of eq. (31), state `[θ, θ̇, z, p]` \[rad, rad/s, m, m\]: the IPCJ
    /// (27); the lag `ż = (C x + D u − z)/τ_s` driven by the IPCJ's ZMP; the Padé term as
    /// `ṗ = (2 z − p)/T`, output `y = p − z`, since `(−s + a)/(s + a) = −1 + 2a/(s + a)` with
    /// `a = 1/T`. `D = 0`: the lag removes the feed-through.
    pub fn state_space(&self) -> StateSpace4 {
        let ip = self.ipcj.state_space();
        let (ts, a) = (self.lag, 1.0 / self.pade);
        let mut am = Matrix4::zeros();
        am.fixed_view_mut::<2, 2>(0, 0).copy_from(&ip.a);
        am[(2, 0)] = ip.c[0] / ts;
        am[(2, 1)] = ip.c[1] / ts;
        am[(2, 2)] = -1.0 / ts;
        am[(3, 2)] = 2.0 * a;
        am[(3, 3)] = -a;
        StateSpace4 {
            a: am,
            b: Vector4::new(0.0, ip.b[1], ip.d / ts, 0.0),
            c: RowVector4::new(0.0, 0.0, -1.0, 1.0),
            d: 0.0,
        }
    }

    /// Transfer function of eq. (31), corrected: the IPCJ times `1/(τ_s s + 1)` times
    /// `(−s + 1/T)/(s + 1/T)`.
    pub fn transfer_function(&self) -> TransferFunction {
        let tf = self.ipcj.transfer_function();
        let a = 1.0 / self.pade;
        TransferFunction {
            numerator: tf.numerator.mul(&Polynomial::new(&[-1.0, a])),
            denominator: tf
                .denominator
                .mul(&Polynomial::new(&[self.lag, 1.0]))
                .mul(&Polynomial::new(&[1.0, a])),
        }
    }

    /// The four poles \[rad/s\] (errata eq. 32): the IPCJ pair, `−1/τ_s`, `−1/T`.
    pub fn poles(&self) -> [Complex<f64>; 4] {
        let [p1, p2] = self.ipcj.poles();
        [
            p1,
            p2,
            Complex::new(-1.0 / self.lag, 0.0),
            Complex::new(-1.0 / self.pade, 0.0),
        ]
    }

    /// The three zeros \[rad/s\]: `±√(g/l)` and the Padé zero `+1/T`.
    pub fn zeros(&self) -> [f64; 3] {
        let [z1, z2] = self.ipcj.zeros();
        [z1, z2, 1.0 / self.pade]
    }

    /// Static gain \[m/rad\], the IPCJ's: the lag and the Padé term have unit static gain.
    pub fn dc_gain(&self) -> f64 {
        self.ipcj.dc_gain()
    }

    /// Frequency response `y/u (jω)` \[m/rad\] at one angular frequency \[rad/s\].
    pub fn frequency_response(&self, omega: f64) -> Complex<f64> {
        let s = Complex::new(0.0, omega);
        let a = 1.0 / self.pade;
        self.ipcj.frequency_response(omega) / (s * self.lag + 1.0) * (a - s) / (s + a)
    }

    /// Bode data at the given angular frequencies \[rad/s\]: magnitude \[m/rad\] and *unwrapped*
    /// phase \[rad\], the phase being the sum of the factors' phases (no ±2π jumps):
    /// `−atan2(b ω/(m l²), K/(m l²) − g/l − ω²) − atan(τ_s ω) − 2 atan(T ω)`.
    pub fn bode(&self, omegas: &[f64]) -> Bode {
        let mut out = Bode {
            omega: Vec::with_capacity(omegas.len()),
            magnitude: Vec::with_capacity(omegas.len()),
            phase: Vec::with_capacity(omegas.len()),
        };
        let wn2 = self.ipcj.stiffness_term() - self.ipcj.gravity / self.ipcj.length;
        for &w in omegas {
            out.omega.push(w);
            out.magnitude.push(self.frequency_response(w).norm());
            let ipcj_phase = -(self.ipcj.damping_term() * w).atan2(wn2 - w * w);
            out.phase
                .push(ipcj_phase - (self.lag * w).atan() - 2.0 * (self.pade * w).atan());
        }
        out
    }
}

/// Bode data: magnitude and phase at a set of angular frequencies.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Bode {
    /// Angular frequencies \[rad/s\].
    pub omega: Vec<f64>,
    /// Magnitudes `|y/u|` \[m/rad\].
    pub magnitude: Vec<f64>,
    /// Phases \[rad\].
    pub phase: Vec<f64>,
}

/// A rational transfer function `numerator(s) / denominator(s)`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TransferFunction {
    /// Numerator polynomial.
    pub numerator: Polynomial,
    /// Denominator polynomial.
    pub denominator: Polynomial,
}

impl TransferFunction {
    /// Value at a complex point `s` \[rad/s\].
    pub fn eval(&self, s: Complex<f64>) -> Complex<f64> {
        self.numerator.eval(s) / self.denominator.eval(s)
    }

    /// Poles: roots of the denominator \[rad/s\].
    pub fn poles(&self) -> Vec<Complex<f64>> {
        self.denominator.roots()
    }

    /// Zeros: roots of the numerator \[rad/s\].
    pub fn zeros(&self) -> Vec<Complex<f64>> {
        self.numerator.roots()
    }
}

/// Continuous state space of the IPCJ: `ẋ = A x + B u`, `y = C x + D u`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateSpace2 {
    /// `A` \[1/s, 1/s²\].
    pub a: Matrix2<f64>,
    /// `B`.
    pub b: Vector2<f64>,
    /// `C` \[m/rad, m·s/rad\].
    pub c: RowVector2<f64>,
    /// `D` \[m/rad\].
    pub d: f64,
}

/// Continuous state space of the full four-state model: `ẋ = A x + B u`, `y = C x + D u`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateSpace4 {
    /// `A`.
    pub a: Matrix4<f64>,
    /// `B`.
    pub b: Vector4<f64>,
    /// `C`.
    pub c: RowVector4<f64>,
    /// `D` \[m/rad\].
    pub d: f64,
}

fn positive(name: &str, value: f64) -> Result<()> {
    check_finite(|| name.to_string(), value)?;
    if value > 0.0 {
        Ok(())
    } else {
        Err(invalid(name, value, "> 0"))
    }
}

pub(crate) fn invalid(name: &str, value: f64, expected: &str) -> Error {
    Error::InvalidSetting {
        name: name.to_string(),
        value: value.to_string(),
        expected: expected.to_string(),
    }
}
