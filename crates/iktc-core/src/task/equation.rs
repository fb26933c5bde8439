//! The plain data every task linearises to: J q̈ = h.

use nalgebra::{DMatrix, DVector};

use crate::error::{check_finite, Error, Result};

/// CLIK gains of a task (paper eq. 11): ẍ = ẍ_d + k_v (ẋ_d − ẋ) + k_p (x_d − x).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Gains {
    /// Position gain k_p \[1/s²\].
    pub kp: f64,
    /// Velocity gain k_v \[1/s\].
    pub kv: f64,
}

impl Gains {
    /// Critically damped gains for a given k_p \[1/s²\]: k_v = 2 √k_p. The paper's 3R
    /// experiment uses k_p = 100 s⁻², k_v = 20 s⁻¹.
    pub fn critical(kp: f64) -> Self {
        Self {
            kp,
            kv: 2.0 * kp.max(0.0).sqrt(),
        }
    }

    /// Checks that both gains are finite and non-negative.
    pub fn validate(&self) -> Result<()> {
        for (n, v) in [("kp", self.kp), ("kv", self.kv)] {
            check_finite(|| format!("gain {n}"), v)?;
            if v < 0.0 {
                return Err(Error::InvalidSetting {
                    name: format!("gain {n}"),
                    value: v.to_string(),
                    expected: "a non-negative number".into(),
                });
            }
        }
        Ok(())
    }
}

impl Gains {
    /// The longest control period \[s\] at which a task under these gains is tracked stably
    /// when its q̈ is held over the period (q̇ ← q̇ + q̈ Δt, q ← q + q̇ Δt): the error then
    /// follows `z² − (2 − k_v Δt − k_p Δt²) z + (1 − k_v Δt)`, whose roots lie inside the unit
    /// circle (Jury) iff `k_v Δt < 2` and `k_p Δt² + 2 k_v Δt < 4`. Critically damped at ω
    /// (`k_p = ω²`, `k_v = 2ω`) that is `ω Δt < 2√2 − 2 ≈ 0.828`: 0.083 s at the default
    /// ω = 10 rad/s, 0.041 s at 20 rad/s. Infinite for zero gains.
    pub fn max_stable_dt(&self) -> f64 {
        let by_rate = if self.kv > 0.0 {
            2.0 / self.kv
        } else {
            f64::INFINITY
        };
        // Positive root of k_p Δt² + 2 k_v Δt − 4 = 0.
        let by_sum = if self.kp > 0.0 {
            (-self.kv + (self.kv * self.kv + 4.0 * self.kp).sqrt()) / self.kp
        } else if self.kv > 0.0 {
            2.0 / self.kv
        } else {
            f64::INFINITY
        };
        by_rate.min(by_sum)
    }
}

impl Default for Gains {
    fn default() -> Self {
        Self::critical(100.0)
    }
}

/// One level of the hierarchy as plain data (eqs. 2, 3, 11): `jacobian · q̈ = rhs`, with
/// rhs = ẍ_d + k_v (ẋ_d − ẋ) + k_p (x_d − x) − J̇q̇, plus the current errors for reporting.
#[derive(Debug, Clone, PartialEq)]
pub struct TaskEquation {
    /// A name for reports ("feet", "com", …).
    pub name: String,
    /// J, m × nv.
    pub jacobian: DMatrix<f64>,
    /// h, length m \[task unit/s²\].
    pub rhs: DVector<f64>,
    /// x_d − x, length m \[task unit\] (rotation vector \[rad\] for orientations).
    pub error: DVector<f64>,
    /// ẋ_d − ẋ, length m \[task unit/s\].
    pub error_rate: DVector<f64>,
}

impl TaskEquation {
    /// A zero equation of `m` rows for `nv` velocity coordinates.
    pub fn zeros(name: impl Into<String>, m: usize, nv: usize) -> Self {
        Self {
            name: name.into(),
            jacobian: DMatrix::zeros(m, nv),
            rhs: DVector::zeros(m),
            error: DVector::zeros(m),
            error_rate: DVector::zeros(m),
        }
    }

    /// Number of rows m.
    pub fn dim(&self) -> usize {
        self.rhs.len()
    }

    /// Number of columns nv.
    pub fn nv(&self) -> usize {
        self.jacobian.ncols()
    }

    /// Checks that a task of `dim` rows fits at `offset` and that the columns are `nv`; `what`
    /// names the task in the error (formatted only on failure: this runs every tick).
    pub(crate) fn check_room(
        &self,
        nv: usize,
        offset: usize,
        dim: usize,
        what: impl FnOnce() -> String,
    ) -> Result<()> {
        crate::error::check_dim("task equation columns (nv)", nv, self.nv())?;
        if offset + dim > self.dim() {
            return Err(Error::DimensionMismatch {
                what: format!("rows of the task equation for {}", what()),
                expected: offset + dim,
                got: self.dim(),
            });
        }
        Ok(())
    }

    /// Checks that sizes agree and every entry is finite.
    pub fn validate(&self) -> Result<()> {
        // Messages are formatted only on failure: this runs every tick and must not allocate.
        let m = self.rhs.len();
        if self.jacobian.nrows() != m {
            return crate::error::check_dim(
                &format!("rows of J of `{}`", self.name),
                m,
                self.jacobian.nrows(),
            );
        }
        if !crate::error::all_finite(self.jacobian.as_slice()) {
            return crate::error::check_all_finite(
                &format!("J of `{}`", self.name),
                self.jacobian.as_slice(),
            );
        }
        if !crate::error::all_finite(self.rhs.as_slice()) {
            return crate::error::check_all_finite(
                &format!("h of `{}`", self.name),
                self.rhs.as_slice(),
            );
        }
        Ok(())
    }
}

/// Copies row `k` of `src` (a column-major Jacobian of nv columns, e.g. a frame's 6 × nv)
/// into row `r` of `out`'s J, column by column over the two column-major storages.
#[inline]
pub(crate) fn copy_jacobian_row(out: &mut TaskEquation, r: usize, src: &DMatrix<f64>, k: usize) {
    let (m, sr) = (out.jacobian.nrows(), src.nrows());
    let dst = out.jacobian.as_mut_slice().chunks_exact_mut(m);
    for (jc, sc) in dst.zip(src.as_slice().chunks_exact(sr)) {
        jc[r] = sc[k];
    }
}

/// Writes row `r` of a task but its J row: error e, error rate ė, reference acceleration
/// a_d and drift d, so that h = a_d + k_v ė + k_p e − d.
#[inline]
pub(crate) fn write_row(
    out: &mut TaskEquation,
    r: usize,
    e: f64,
    edot: f64,
    acc_ref: f64,
    drift: f64,
    gains: &Gains,
) {
    out.error[r] = e;
    out.error_rate[r] = edot;
    out.rhs[r] = acc_ref + gains.kv * edot + gains.kp * e - drift;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Near the bound the error's slower root crosses the unit circle: the recursion
    /// e_{k+2} = (2 − k_v Δt − k_p Δt²) e_{k+1} − (1 − k_v Δt) e_k decays at 0.99 of the
    /// bound and grows at 1.01 of it.
    #[test]
    fn the_stable_period_bound_separates_decay_from_growth() {
        for g in [
            Gains::critical(100.0),
            Gains::critical(400.0),
            Gains { kp: 50.0, kv: 40.0 },
        ] {
            let bound = g.max_stable_dt();
            let run = |dt: f64| {
                let (a1, a0) = (2.0 - g.kv * dt - g.kp * dt * dt, 1.0 - g.kv * dt);
                let (mut e0, mut e1) = (1.0f64, 1.0f64);
                for _ in 0..20_000 {
                    (e0, e1) = (e1, a1 * e1 - a0 * e0);
                }
                e1.abs()
            };
            assert!(run(0.99 * bound) < 1e-3, "{g:?} {bound}");
            assert!(run(1.01 * bound) > 1e3, "{g:?} {bound}");
        }
        // ω = 20 rad/s: (2√2 − 2)/20.
        let b = Gains::critical(400.0).max_stable_dt();
        assert!((b - (8f64.sqrt() - 2.0) / 20.0).abs() < 1e-12, "{b}");
    }
}
