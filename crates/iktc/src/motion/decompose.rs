//! Decomposition of a rotation into rotations about given joint axes, for retargeting a captured
//! joint rotation onto a robot's 1–3 revolute joints (see [`decompose_rotation`]).

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use super::angles::{nearest_equivalent, wrap_to_pi};
use crate::error::{check_dim, Error, Result};

/// The largest number of axes [`decompose_rotation`] accepts.
pub const MAX_DECOMPOSITION_AXES: usize = 3;

/// Thresholds of [`decompose_rotation_with`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DecomposeSettings {
    /// Largest `|a_i · a_j|` \[–\] for which consecutive axes count as orthogonal, so that three
    /// axes are decomposed in closed form. Larger values send nearly orthogonal axes to the closed
    /// form, whose small error the Gauss–Newton polish then removes; smaller values send them to
    /// the slower iterative path. Default 1e-9.
    pub orthogonality_tolerance: f64,
    /// `|sin(θ_2 − λ)|` \[–\] below which a three-axis decomposition is treated as gimbal-locked
    /// (and, for one axis, the norm of the quaternion's part `(w, v·a)` below which the twist is
    /// undefined). Larger values give smoother tracks near the singularity at the price of a
    /// Gauss–Newton polish over a wider band; smaller values let rounding noise of `R`, amplified
    /// by `1/|sin(θ_2 − λ)|`, reach `θ_1` and `θ_3`. Default 1e-7.
    pub singularity_tolerance: f64,
    /// Largest number of Gauss–Newton iterations per seed \[–\]. More iterations polish harder
    /// cases (far seeds, non-orthogonal axes) at a proportional cost. Default 50.
    pub max_iterations: usize,
    /// Largest number of step halvings per Gauss–Newton iteration \[–\] before the iteration stops
    /// for lack of progress. Default 30.
    pub max_step_halvings: usize,
    /// Gauss–Newton stops when the accepted step is shorter than this \[rad\]. Smaller values
    /// polish to the last digits at the cost of an extra iteration or two. Default 1e-12.
    pub step_tolerance: f64,
    /// Levenberg damping `μ` \[–\] added to the diagonal of `JᵀJ`: keeps the step bounded at
    /// singular configurations (where it also keeps the angles near their seed) and costs
    /// convergence speed when too large. Default 1e-9.
    pub damping: f64,
    /// Smallest accepted norm of a given axis \[–\] (axes are normalised). Default 1e-9.
    pub min_axis_norm: f64,
    /// Solutions whose residual angles differ by less than this \[rad\] count as equally good; among
    /// them the one nearest to `previous` wins. Larger values favour continuity over the last
    /// digits of the fit. Default 1e-9.
    pub equivalence_tolerance: f64,
}

impl Default for DecomposeSettings {
    fn default() -> Self {
        Self {
            orthogonality_tolerance: 1e-9,
            singularity_tolerance: 1e-7,
            max_iterations: 50,
            max_step_halvings: 30,
            step_tolerance: 1e-12,
            damping: 1e-9,
            min_axis_norm: 1e-9,
            equivalence_tolerance: 1e-9,
        }
    }
}

impl DecomposeSettings {
    /// Checks that every threshold is finite and in its range.
    pub fn validate(&self) -> Result<()> {
        let unit_interval = [
            ("orthogonality_tolerance", self.orthogonality_tolerance),
            ("singularity_tolerance", self.singularity_tolerance),
        ];
        for (name, value) in unit_interval {
            if !(value.is_finite() && (0.0..1.0).contains(&value)) {
                return Err(invalid(name, value, "a finite number in [0, 1)"));
            }
        }
        let positive = [
            ("step_tolerance", self.step_tolerance),
            ("damping", self.damping),
            ("min_axis_norm", self.min_axis_norm),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(invalid(name, value, "a finite number > 0"));
            }
        }
        if !(self.equivalence_tolerance.is_finite() && self.equivalence_tolerance >= 0.0) {
            return Err(invalid(
                "equivalence_tolerance",
                self.equivalence_tolerance,
                "a finite number >= 0",
            ));
        }
        Ok(())
    }
}

fn invalid(name: &str, value: f64, expected: &str) -> Error {
    Error::InvalidSetting {
        name: name.to_string(),
        value: value.to_string(),
        expected: expected.to_string(),
    }
}

/// How a decomposition was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DecompositionMethod {
    /// Three consecutively orthogonal axes, closed form (Davenport / Euler angles).
    ClosedForm {
        /// Whether the configuration was gimbal-locked and `θ_1 + σθ_3` was split by the
        /// nearest-to-previous rule.
        singular: bool,
    },
    /// One axis: the twist of the swing–twist decomposition.
    Twist {
        /// Whether the twist was undefined (the previous angle, or 0, was kept).
        singular: bool,
    },
    /// Two axes, or three axes that are not consecutively orthogonal: seeds and Gauss–Newton.
    LeastSquares,
}

/// What [`decompose_rotation`] reports besides the angles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decomposition {
    /// Which path produced the angles.
    pub method: DecompositionMethod,
    /// Angle of the residual rotation `R · R(θ)ᵀ` \[rad\]: 0 (to rounding) when `R` is represented
    /// exactly by the axes, otherwise the least-squares misfit.
    pub residual: f64,
    /// Gauss–Newton iterations carried out in total (over all seeds) \[–\].
    pub iterations: usize,
}

/// Decomposes `r` into rotations about `axes` (1 to 3 of them) with the default
/// [`DecomposeSettings`].
///
/// Given a rotation `R` and an ordered list of unit axes `a_1 … a_k` (k = 1, 2 or 3), find angles
/// `θ_1 … θ_k` \[rad\] such that
///
/// ```text
/// R ≈ Rot(a_1, θ_1) · Rot(a_2, θ_2) · … · Rot(a_k, θ_k)
/// ```
///
/// where `Rot(a, θ)` is the right-handed rotation by `θ` about `a` and the product acts on column
/// vectors (the rightmost factor is applied first to a vector; read left to right it is a sequence
/// of *intrinsic* rotations: first about `a_1`, then about the moved `a_2`, …). Each axis is
/// given in its own joint frame at zero angle, which for a serial chain of joints sharing one
/// origin frame (a robot's shoulder pitch–roll–yaw at zero) is the parent frame of `R`: the
/// axes of the chain at its zero configuration.
///
/// Three cases:
///
/// * **k = 3 with `a_1 ⊥ a_2` and `a_2 ⊥ a_3`** (all Tait–Bryan and proper Euler orders and their
///   generalisation, the *Davenport angles*): closed form (Shuster & Markley, "Generalization of
///   Euler angles", J. Astronaut. Sci. 51(2), 2003). With `λ = atan2(a_1·(a_2×a_3), a_1·a_3)`:
///   `a_1ᵀ R a_3 = cos(θ_2 − λ)`, so `θ_2 = λ ± β` with `β = atan2(‖w − (a_1·w)a_1‖, a_1·w)`,
///   `w = R a_3`; then `θ_1` is the angle about `a_1` taking `Rot(a_2, θ_2) a_3` to `R a_3`, and
///   `θ_3` the angle about `a_3` taking `Rᵀ a_1` to `Rot(a_2, θ_2)ᵀ a_1`. Every rotation is
///   represented. The result is polished by the Gauss–Newton iteration below (normally 0–1 steps).
/// * **k = 1**: the *twist* of the swing–twist decomposition, `θ = 2·atan2(v·a, w)` for
///   `R = (w, v)` as a unit quaternion. It is the exact least-squares answer: it minimises the
///   angle of the residual rotation `R · Rot(a, θ)ᵀ`.
/// * **k = 2, or 3 axes that are not consecutively orthogonal**: seeds from projections (for two
///   axes, `θ_1` turns `a_2` about `a_1` towards `R a_2`, then `θ_2` is the twist of the remainder
///   about `a_2`; sequential twists for three), the previous angles if given, then damped
///   Gauss–Newton on the residual rotation vector `e(θ) = log(R · R(θ)ᵀ)` (spatial frame) with the
///   Jacobian columns `J_i = Rot(a_1,θ_1)⋯Rot(a_{i−1},θ_{i−1}) a_i`:
///   `(JᵀJ + μI) δ = Jᵀe`, `θ ← θ + δ` with step halving while the residual does not decrease.
///   The result is a local least-squares solution (the smallest residual over the seeds); it is
///   exact whenever `R` is representable and a seed lies in the basin of the solution.
///
/// **Choice among equivalent solutions.** Angles are defined modulo 2π, and three-axis
/// decompositions have two branches (`θ_2 = λ ± β`). Without `previous`, every angle is wrapped
/// into (−π, π] and the branch with the smaller `|θ_2|` is taken (for the Tait–Bryan orders this is
/// `θ_2 ∈ \[−π/2, π/2\]`; for proper Euler orders, `θ_2 ∈ \[0, π\]`). With `previous`, the branch and
/// the 2π-equivalent of every angle that are nearest (in Euclidean distance) to the previous angles
/// are taken, so a track decomposed frame after frame stays continuous and may leave (−π, π].
///
/// **Singular case (gimbal lock).** When `a_1` and `Rot(a_2, θ_2) a_3` are parallel
/// (`|sin(θ_2 − λ)|` below [`DecomposeSettings::singularity_tolerance`]), only
/// `φ = θ_1 + σθ_3` is determined (`σ = ±1`, the sign of `cos(θ_2 − λ)`). Then `φ` is split so that
/// `(θ_1, θ_3)` is nearest to the previous angles: `θ_1 = p_1 + d/2`, `θ_3 = p_3 + σd/2` with
/// `d = φ − (p_1 + σp_3)` (φ taken modulo 2π nearest to `p_1 + σp_3`); without `previous`,
/// `θ_3 = 0`. The same rule applies to one axis when the twist is undefined (`R` a half turn about
/// an axis perpendicular to `a`): the previous angle, or 0, is kept.
///
/// `out` receives `θ_1 … θ_k` \[rad\] and must have the length of `axes`; `previous`, if given,
/// too. Errors: 0 or more than [`MAX_DECOMPOSITION_AXES`] axes, a length mismatch, a non-finite
/// input, an axis of (near) zero length. Allocates nothing.
pub fn decompose_rotation(
    r: &UnitQuaternion<f64>,
    axes: &[Vector3<f64>],
    previous: Option<&[f64]>,
    out: &mut [f64],
) -> Result<Decomposition> {
    decompose_rotation_with(r, axes, previous, &DecomposeSettings::default(), out)
}

/// [`decompose_rotation`] with explicit settings.
pub fn decompose_rotation_with(
    r: &UnitQuaternion<f64>,
    axes: &[Vector3<f64>],
    previous: Option<&[f64]>,
    settings: &DecomposeSettings,
    out: &mut [f64],
) -> Result<Decomposition> {
    settings.validate()?;
    let k = axes.len();
    if k == 0 || k > MAX_DECOMPOSITION_AXES {
        return Err(Error::InvalidSetting {
            name: "axes".to_string(),
            value: format!("{k} axes"),
            expected: format!("1 to {MAX_DECOMPOSITION_AXES} joint axes"),
        });
    }
    check_dim("decomposition output angles", k, out.len())?;
    if let Some(q) = r.coords.iter().find(|c| !c.is_finite()) {
        return Err(Error::NonFinite {
            what: "rotation to decompose".to_string(),
            value: *q,
        });
    }
    let mut prev = [0.0; MAX_DECOMPOSITION_AXES];
    let prev = match previous {
        Some(p) => {
            check_dim("previous angles", k, p.len())?;
            for (i, (slot, value)) in prev.iter_mut().zip(p).enumerate() {
                if !value.is_finite() {
                    return Err(Error::NonFinite {
                        what: format!("previous angles[{i}]"),
                        value: *value,
                    });
                }
                *slot = *value;
            }
            Some(prev)
        }
        None => None,
    };
    let mut n = [Vector3::zeros(); MAX_DECOMPOSITION_AXES];
    for (i, (slot, axis)) in n.iter_mut().zip(axes).enumerate() {
        if let Some(c) = axis.iter().find(|c| !c.is_finite()) {
            return Err(Error::NonFinite {
                what: format!("axes[{i}]"),
                value: *c,
            });
        }
        let norm = axis.norm();
        if norm < settings.min_axis_norm {
            return Err(Error::InvalidSetting {
                name: format!("axes[{i}]"),
                value: format!("({}, {}, {})", axis.x, axis.y, axis.z),
                expected: format!("a joint axis of norm >= {}", settings.min_axis_norm),
            });
        }
        *slot = axis / norm;
    }
    let problem = Problem {
        target: *r,
        n,
        k,
        prev,
        settings,
    };
    let (theta, report) = match k {
        1 => problem.twist(),
        3 if problem.is_davenport() => problem.closed_form(),
        _ => problem.least_squares(),
    };
    for (o, t) in out.iter_mut().zip(theta.iter()) {
        *o = *t;
    }
    Ok(report)
}

/// Composes `Rot(a_1, θ_1) · … · Rot(a_k, θ_k)` (the inverse of [`decompose_rotation`]); the axes
/// are normalised. Errors on a length mismatch, a non-finite input or a zero axis.
pub fn compose_rotation(axes: &[Vector3<f64>], angles: &[f64]) -> Result<UnitQuaternion<f64>> {
    check_dim("angles", axes.len(), angles.len())?;
    let mut q = UnitQuaternion::identity();
    for (i, (axis, angle)) in axes.iter().zip(angles).enumerate() {
        crate::error::check_finite(|| format!("angles[{i}]"), *angle)?;
        crate::error::check_all_finite("axis", axis.as_slice())?;
        let norm = axis.norm();
        if norm == 0.0 {
            return Err(Error::InvalidSetting {
                name: format!("axes[{i}]"),
                value: "(0, 0, 0)".to_string(),
                expected: "a non-zero joint axis".to_string(),
            });
        }
        q *= axis_rotation(&(axis / norm), *angle);
    }
    Ok(q)
}

/// `Rot(n, θ)` for a unit axis `n`.
fn axis_rotation(n: &Vector3<f64>, angle: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_scaled_axis(n * angle)
}

/// Angle \[rad\] of a rotation, in \[0, π\], computed without the loss of precision of `acos`.
pub fn rotation_angle(q: &UnitQuaternion<f64>) -> f64 {
    2.0 * q.imag().norm().atan2(q.w.abs())
}

/// Rotation vector (axis × angle, angle in \[0, π\]) of a unit quaternion, precise near identity.
fn log(q: &UnitQuaternion<f64>) -> Vector3<f64> {
    let (w, v) = if q.w < 0.0 {
        (-q.w, -q.imag())
    } else {
        (q.w, q.imag())
    };
    let s = v.norm();
    if s == 0.0 {
        return Vector3::zeros();
    }
    v * (2.0 * s.atan2(w) / s)
}

/// Signed angle \[rad\] about the unit `axis` that turns the projection of `from` onto the plane
/// normal to `axis` onto the projection of `to` (0 if either projection vanishes).
fn signed_angle(axis: &Vector3<f64>, from: &Vector3<f64>, to: &Vector3<f64>) -> f64 {
    let y = axis.dot(&from.cross(to));
    let x = from.dot(to) - axis.dot(from) * axis.dot(to);
    if x == 0.0 && y == 0.0 {
        0.0
    } else {
        y.atan2(x)
    }
}

struct Problem<'a> {
    target: UnitQuaternion<f64>,
    n: [Vector3<f64>; MAX_DECOMPOSITION_AXES],
    k: usize,
    prev: Option<[f64; MAX_DECOMPOSITION_AXES]>,
    settings: &'a DecomposeSettings,
}

type Angles = [f64; MAX_DECOMPOSITION_AXES];

impl Problem<'_> {
    fn compose(&self, theta: &Angles) -> UnitQuaternion<f64> {
        let mut q = UnitQuaternion::identity();
        for (n, t) in self.n.iter().zip(theta).take(self.k) {
            q *= axis_rotation(n, *t);
        }
        q
    }

    /// Residual rotation vector `log(R · R(θ)ᵀ)` (spatial frame).
    fn error(&self, theta: &Angles) -> Vector3<f64> {
        log(&(self.target * self.compose(theta).inverse()))
    }

    fn is_davenport(&self) -> bool {
        let tol = self.settings.orthogonality_tolerance;
        self.n[0].dot(&self.n[1]).abs() <= tol && self.n[1].dot(&self.n[2]).abs() <= tol
    }

    /// Wraps every angle to its equivalent nearest to the previous angles, or into (−π, π].
    fn place(&self, theta: &mut Angles) {
        for (i, t) in theta.iter_mut().enumerate().take(self.k) {
            *t = match self.prev {
                Some(p) => nearest_equivalent(*t, p[i]),
                None => wrap_to_pi(*t),
            };
        }
    }

    fn distance_to_prev(&self, theta: &Angles) -> f64 {
        match self.prev {
            Some(p) => theta
                .iter()
                .zip(p.iter())
                .take(self.k)
                .map(|(a, b)| (a - b) * (a - b))
                .sum(),
            None => 0.0,
        }
    }

    fn twist(&self) -> (Angles, Decomposition) {
        let a = self.n[0];
        let w = self.target.w;
        let p = self.target.imag().dot(&a);
        let singular = w.hypot(p) < self.settings.singularity_tolerance;
        let mut theta = [0.0; MAX_DECOMPOSITION_AXES];
        theta[0] = if singular {
            self.prev.map_or(0.0, |prev| prev[0])
        } else {
            2.0 * p.atan2(w)
        };
        self.place(&mut theta);
        let residual = self.error(&theta).norm();
        (
            theta,
            Decomposition {
                method: DecompositionMethod::Twist { singular },
                residual,
                iterations: 0,
            },
        )
    }

    fn closed_form(&self) -> (Angles, Decomposition) {
        let [n1, n2, n3] = self.n;
        let r = self.target.to_rotation_matrix().into_inner();
        let lambda = n1.dot(&n2.cross(&n3)).atan2(n1.dot(&n3));
        let w = r * n3;
        let cos_b = n1.dot(&w);
        let sin_b = (w - n1 * cos_b).norm();
        let beta = sin_b.atan2(cos_b);
        let singular = sin_b < self.settings.singularity_tolerance;
        let sigma = if cos_b >= 0.0 { 1.0 } else { -1.0 };
        let mut best: Option<(Angles, f64)> = None;
        for theta2 in [lambda + beta, lambda - beta] {
            let r2 = axis_rotation(&n2, theta2).to_rotation_matrix().into_inner();
            let (t1, t3) = if singular {
                let m = r * r2.transpose();
                let phi = signed_angle(&n1, &n2, &(m * n2));
                self.split(phi, sigma)
            } else {
                let v = r2 * n3;
                let t1 = signed_angle(&n1, &v, &w);
                let u = r2.transpose() * n1;
                let x = r.transpose() * n1;
                (t1, signed_angle(&n3, &x, &u))
            };
            let mut candidate = [t1, theta2, t3];
            self.place(&mut candidate);
            let score = match self.prev {
                Some(_) => self.distance_to_prev(&candidate),
                None => candidate[1].abs(),
            };
            if best.is_none_or(|(_, s)| score < s) {
                best = Some((candidate, score));
            }
        }
        let mut theta = best.map_or([0.0; MAX_DECOMPOSITION_AXES], |(t, _)| t);
        let (residual, iterations) = self.gauss_newton(&mut theta);
        self.place(&mut theta);
        (
            theta,
            Decomposition {
                method: DecompositionMethod::ClosedForm { singular },
                residual,
                iterations,
            },
        )
    }

    /// Splits `φ = θ_1 + σθ_3` nearest to the previous angles (or with `θ_3 = 0`).
    fn split(&self, phi: f64, sigma: f64) -> (f64, f64) {
        match self.prev {
            Some(p) => {
                let sum = p[0] + sigma * p[2];
                let d = nearest_equivalent(phi, sum) - sum;
                (p[0] + 0.5 * d, p[2] + sigma * 0.5 * d)
            }
            None => (phi, 0.0),
        }
    }

    fn least_squares(&self) -> (Angles, Decomposition) {
        let mut seeds: [Option<Angles>; 3] = [None; 3];
        // Seed 1: θ_1 turns a_2 about a_1 towards R a_2, θ_2 (and θ_3) are twists of the rest.
        let r = self.target;
        let mut s1 = [0.0; MAX_DECOMPOSITION_AXES];
        s1[0] = signed_angle(&self.n[0], &self.n[1], &(r * self.n[1]));
        let mut rest = axis_rotation(&self.n[0], s1[0]).inverse() * r;
        for (t, n) in s1.iter_mut().zip(self.n.iter()).take(self.k).skip(1) {
            *t = twist_angle(&rest, n);
            rest = axis_rotation(n, *t).inverse() * rest;
        }
        seeds[0] = Some(s1);
        // Seed 2: sequential twists.
        let mut s2 = [0.0; MAX_DECOMPOSITION_AXES];
        let mut rest = r;
        for (t, n) in s2.iter_mut().zip(self.n.iter()).take(self.k) {
            *t = twist_angle(&rest, n);
            rest = axis_rotation(n, *t).inverse() * rest;
        }
        seeds[1] = Some(s2);
        // Seed 3: the previous angles.
        seeds[2] = self.prev;

        let mut best: Option<(Angles, f64, f64)> = None;
        let mut iterations = 0;
        for seed in seeds.into_iter().flatten() {
            let mut theta = seed;
            let (residual, it) = self.gauss_newton(&mut theta);
            iterations += it;
            self.place(&mut theta);
            let distance = self.distance_to_prev(&theta);
            let better = match best {
                None => true,
                Some((_, best_res, best_dist)) => {
                    let tol = self.settings.equivalence_tolerance;
                    residual < best_res - tol
                        || (residual <= best_res + tol && distance < best_dist)
                }
            };
            if better {
                best = Some((theta, residual, distance));
            }
        }
        let (theta, residual) =
            best.map_or(([0.0; MAX_DECOMPOSITION_AXES], f64::NAN), |b| (b.0, b.1));
        (
            theta,
            Decomposition {
                method: DecompositionMethod::LeastSquares,
                residual,
                iterations,
            },
        )
    }

    /// Damped Gauss–Newton on `e(θ) = log(R · R(θ)ᵀ)`; returns the final residual angle and the
    /// number of iterations.
    fn gauss_newton(&self, theta: &mut Angles) -> (f64, usize) {
        let s = self.settings;
        let mut e = self.error(theta);
        let mut residual = e.norm();
        let mut iterations = 0;
        while iterations < s.max_iterations && residual > 0.0 {
            let mut jac = Matrix3::zeros();
            let mut prefix = UnitQuaternion::identity();
            for (i, (n, t)) in self.n.iter().zip(theta.iter()).take(self.k).enumerate() {
                jac.set_column(i, &(prefix * n));
                prefix *= axis_rotation(n, *t);
            }
            let mut normal = jac.transpose() * jac;
            for i in 0..MAX_DECOMPOSITION_AXES {
                normal[(i, i)] += if i < self.k { s.damping } else { 1.0 };
            }
            let Some(chol) = normal.cholesky() else { break };
            let delta = chol.solve(&(jac.transpose() * e));
            iterations += 1;
            let mut step = 1.0;
            let mut accepted = false;
            for _ in 0..=s.max_step_halvings {
                let mut trial = *theta;
                for (t, d) in trial.iter_mut().zip(delta.iter()).take(self.k) {
                    *t += step * d;
                }
                let e_trial = self.error(&trial);
                let r_trial = e_trial.norm();
                if r_trial < residual {
                    *theta = trial;
                    e = e_trial;
                    residual = r_trial;
                    accepted = true;
                    break;
                }
                step *= 0.5;
            }
            if !accepted || step * delta.norm() < s.step_tolerance {
                break;
            }
        }
        (residual, iterations)
    }
}

/// Twist angle of `q` about the unit axis `a` \[rad\] (0 where undefined).
fn twist_angle(q: &UnitQuaternion<f64>, a: &Vector3<f64>) -> f64 {
    let p = q.imag().dot(a);
    if p == 0.0 && q.w == 0.0 {
        0.0
    } else {
        wrap_to_pi(2.0 * p.atan2(q.w))
    }
}
