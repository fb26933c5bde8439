//! Continuity of IKTC's corrected level from one tick to the next: a hold on Algorithm 2's
//! choice.
//!
//! Algorithm 2 corrects from `f_k`, the lowest-priority level whose correction brings q̈ into
//! the box at tick k. Near the boundary between two levels `f_k` can alternate tick by tick:
//! a correction of the pelvis level makes room at a joint limit, the next tick the upper-body
//! level suffices, the tick after it does not. The sacrificed accelerations then switch at half
//! the control rate. The hold removes that alternation:
//!
//! ```text
//! c_k = c_{k−1}   if f_k > c_{k−1} and f_j > c_{k−1} for fewer than H consecutive ticks j ≤ k,
//! c_k = f_k       otherwise,
//! ```
//!
//! where `c_k` is the level corrected from and `H` is
//! [`SolverSettings::level_hold`](super::SolverSettings::level_hold). A level that had to be
//! corrected stays corrected until a lower-priority one has sufficed for `H` ticks in a row; a
//! climb to a higher level is never delayed. Holding is always possible: feasibility is monotone
//! in the level (see [`Climb`](super::Climb)), so `f_k > c_{k−1}` means the correction of levels
//! `c_{k−1}..n_T` is feasible too. The box is therefore met exactly at every tick and the levels
//! above `c_k` are untouched (strict priority); what the hold trades is that the levels
//! `c_k..f_k − 1` are corrected for up to `H − 1` ticks longer than Algorithm 2 would. Ticks
//! without any correction count as ticks where a lower level sufficed.
//!
//! **Continuity of the correction itself.** The hold keeps the level; the correction can still
//! jump when the level changes, because the least-norm correction of levels `c..n_T` need not be
//! near the least-norm correction of levels `c'..n_T`. With
//! [`SolverSettings::continuity`](super::SolverSettings::continuity) `μ > 0` the correction QP
//! of eq. (23) becomes
//!
//! ```text
//! min ½‖Δh‖² + ½μ‖q̈₀ + G Δh − q̈₋‖²   s.t.   b_l ≤ q̈₀ + G Δh ≤ b_u,
//! H = I + μ GᵀG,   c = μ Gᵀ(q̈₀ − q̈₋),
//! ```
//!
//! with `q̈₀` the prioritized solution, `G` the columns of the corrected levels and `q̈₋` the
//! previous solve's q̈. The constraints are those of eq. (23), so the feasibility of each level,
//! hence Algorithm 2's choice, the box and the strict priority of the levels above the corrected
//! one, are unchanged; `H` is positive definite for every `G` (`I` plus a positive
//! semi-definite term). Only which feasible correction is taken changes: the one whose q̈ is
//! nearer the last command.

/// The hold's state between ticks. Plain data; `H ≤ 1` makes it Algorithm 2 exactly.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct LevelHold {
    /// The level corrected from at the last corrected tick, while it is held.
    held: Option<usize>,
    /// Consecutive ticks at which a lower-priority level (or none) sufficed.
    easier: usize,
}

impl LevelHold {
    /// The level to correct from this tick, given Algorithm 2's `found`, with hold `hold`
    /// \[ticks\]. Never returns a level below `found` (a lower level is infeasible).
    pub(crate) fn choose(&mut self, found: usize, hold: usize) -> usize {
        match self.held {
            Some(h) if h < found && self.easier + 1 < hold => {
                self.easier += 1;
                h
            }
            _ => {
                self.held = Some(found);
                self.easier = 0;
                found
            }
        }
    }

    /// A tick without correction (q̈ inside the box) or with a fallback: counts as a tick where
    /// a lower level sufficed; releases the held level after `hold` such ticks.
    pub(crate) fn idle(&mut self, hold: usize) {
        self.easier += 1;
        if self.easier >= hold {
            *self = Self::default();
        }
    }

    /// The held level, if any.
    #[cfg(test)]
    pub(crate) fn held(&self) -> Option<usize> {
        self.held
    }
}

#[cfg(test)]
mod tests {
    use super::LevelHold;

    /// The alternation 4, 2, 4, 2, … of Algorithm 2 becomes 4, 2, 2, 2, …: no level change is
    /// undone at the next tick; a lower level takes over after `H` ticks of sufficing.
    #[test]
    fn hold_removes_alternation_and_releases_after_h_ticks() {
        let mut hold = LevelHold::default();
        let found = [4, 2, 4, 2, 4, 2, 4, 4, 4, 4, 4, 4];
        let chosen: Vec<usize> = found.iter().map(|&f| hold.choose(f, 5)).collect();
        assert_eq!(chosen, [4, 2, 2, 2, 2, 2, 2, 2, 2, 2, 4, 4]);
        // Never below Algorithm 2's level.
        assert!(chosen.iter().zip(found).all(|(&c, f)| c <= f));
        // H = 1: Algorithm 2 exactly.
        let mut exact = LevelHold::default();
        let same: Vec<usize> = found.iter().map(|&f| exact.choose(f, 1)).collect();
        assert_eq!(same, found);
    }

    #[test]
    fn ticks_without_correction_release_the_hold() {
        let mut hold = LevelHold::default();
        assert_eq!(hold.choose(1, 3), 1);
        hold.idle(3);
        assert_eq!(hold.held(), Some(1));
        assert_eq!(hold.choose(3, 3), 1);
        hold.idle(3);
        assert_eq!(hold.held(), None);
        assert_eq!(hold.choose(3, 3), 3);
    }
}
