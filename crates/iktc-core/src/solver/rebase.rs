//! Re-basing the demand of a sacrificed level on what was achieved (errata §3.3).
//!
//! A CLIK level asks for `h_i = ẍ_d + k_v ė + k_p e − J̇q̇`. When a joint limit makes it
//! unreachable, IKTC corrects it by `Δh_i` and the level gets `J_i q̈ = h_i + Δh_i`; but its
//! error keeps growing and the next tick it asks for the full `h_i` again, a push into the limit
//! that the box refuses again — on every tick, and harder as the error grows. The re-base is a
//! back-calculation anti-windup on that demand: each level carries an offset `w_i` (task units
//! /s²), the solver is given `h_i + w_i`, and after each IKTC solve
//!
//! ```text
//! w_i ← (1 − r) (w_i + Δh_i),
//! ```
//!
//! with `r` = [`SolverSettings::rebase_release`](super::SolverSettings::rebase_release). While
//! the limit binds the demand converges on what can be achieved, so the sacrificed level stops
//! pushing: the steady refused part is `Δh_i = r/(1 − r) · w_i`, a small, constant push instead
//! of the full feedback. As soon as the limit lets the level move, nothing is refused, `w_i`
//! decays by the factor `1 − r` per tick and the level recovers its CLIK demand (time constant
//! about `Δt/r`) without a jump. Levels never corrected keep `w_i = 0`: the higher levels and
//! the box are untouched; priorities are exact for the re-based demands. `r = 1` is IKTC as
//! printed.

use nalgebra::DVector;

use crate::task::TaskEquation;

/// The offsets `w_i` and the re-based copies of the levels, sized once.
#[derive(Debug, Clone)]
pub(crate) struct Rebase {
    /// `w_i` per level \[task unit/s²\].
    offsets: Vec<DVector<f64>>,
    /// The levels with `h_i + w_i`, given to the solver.
    pub(crate) levels: Vec<TaskEquation>,
}

impl Rebase {
    /// Zero offsets for levels of sizes `dims` over `nv` coordinates.
    pub(crate) fn new(nv: usize, dims: &[usize]) -> Self {
        Self {
            offsets: dims.iter().map(|&m| DVector::zeros(m)).collect(),
            levels: dims
                .iter()
                .map(|&m| TaskEquation::zeros("re-based level", m, nv))
                .collect(),
        }
    }

    /// Writes `J_i` and `h_i + w_i` of every level into [`Rebase::levels`]. The sizes were
    /// checked by the caller. Allocates nothing.
    pub(crate) fn apply(&mut self, levels: &[TaskEquation]) {
        for ((out, l), w) in self.levels.iter_mut().zip(levels).zip(&self.offsets) {
            out.jacobian.copy_from(&l.jacobian);
            for ((o, h), w) in out.rhs.iter_mut().zip(l.rhs.iter()).zip(w.iter()) {
                *o = h + w;
            }
        }
    }

    /// `w_i ← (1 − r)(w_i + Δh_i)` for every level, `corrections` = the Δh of the last solve
    /// (zero where uncorrected), `release` = `r` in (0, 1].
    pub(crate) fn update(&mut self, corrections: &[DVector<f64>], release: f64) {
        let keep = 1.0 - release;
        for (w, dh) in self.offsets.iter_mut().zip(corrections) {
            for (w, dh) in w.iter_mut().zip(dh.iter()) {
                *w = keep * (*w + dh);
            }
        }
    }

    /// `w_i` of every level \[task unit/s²\].
    #[cfg(test)]
    pub(crate) fn offsets(&self) -> &[DVector<f64>] {
        &self.offsets
    }
}

#[cfg(test)]
mod tests {
    use super::Rebase;
    use crate::task::TaskEquation;
    use nalgebra::DVector;

    /// A constant refusal Δh: the offset settles where the refused part is r/(1 − r) of it;
    /// without refusal it decays geometrically.
    #[test]
    fn offset_absorbs_a_steady_refusal_and_decays_without_one() {
        let mut rb = Rebase::new(2, &[1]);
        let r = 0.2;
        // Demand h = 10, achievable 4: the solver's correction is 4 − (h + w).
        for _ in 0..200 {
            let dh = 4.0 - (10.0 + rb.offsets()[0][0]);
            rb.update(&[DVector::from_element(1, dh)], r);
        }
        let w = rb.offsets()[0][0];
        let dh = 4.0 - (10.0 + w);
        assert!((dh - r / (1.0 - r) * w).abs() < 1e-12);
        // Demand re-based to within r of what is achieved: 10 + w = 4 − dh, |dh| = 6 r.
        assert!((dh + 6.0 * r).abs() < 1e-9, "{dh}");
        for _ in 0..10 {
            rb.update(&[DVector::zeros(1)], r);
        }
        assert!((rb.offsets()[0][0] - w * 0.8f64.powi(10)).abs() < 1e-12);
        // apply: h + w, J copied.
        let mut l = TaskEquation::zeros("x", 1, 2);
        l.rhs[0] = 1.0;
        l.jacobian[(0, 1)] = 3.0;
        rb.apply(std::slice::from_ref(&l));
        assert_eq!(rb.levels[0].rhs[0], 1.0 + rb.offsets()[0][0]);
        assert_eq!(rb.levels[0].jacobian[(0, 1)], 3.0);
    }
}
