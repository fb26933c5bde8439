//! How often IKTC's corrected level changes from one tick to the next.
//!
//! The level a tick corrects from is a discrete choice (Algorithm 2): the lowest-priority
//! level whose correction brings q̈ into the box. Near the boundary between two levels the
//! choice can alternate tick by tick — for instance a correction of the pelvis level makes room
//! at a joint limit, the next tick needs only the joint level, and the tick after needs the
//! pelvis level again. The sacrificed task's acceleration then switches between corrected and
//! uncorrected at half the control rate, which a real robot feels as vibration. These counts
//! make that visible in a run's summary.

use serde::Serialize;

/// Changes of the corrected level between consecutive corrected ticks.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct LevelSwitches {
    /// Pairs of consecutive ticks, both corrected, that corrected from different levels.
    pub switches: usize,
    /// Triples of consecutive corrected ticks whose level goes A, B, A with B ≠ A: a switch
    /// undone at the next tick.
    pub flips: usize,
}

impl LevelSwitches {
    /// Counts over the corrected level of each tick, `None` for a tick without correction
    /// (as [`ImitateStep::corrected_from`](super::ImitateStep::corrected_from)).
    pub fn count(levels: &[Option<usize>]) -> Self {
        let switches = levels
            .windows(2)
            .filter(|w| w[0].is_some() && w[1].is_some() && w[0] != w[1])
            .count();
        let flips = levels
            .windows(3)
            .filter(|w| w.iter().all(Option::is_some) && w[0] == w[2] && w[0] != w[1])
            .count();
        Self { switches, flips }
    }
}

#[cfg(test)]
mod tests {
    use super::LevelSwitches;

    #[test]
    fn counts_switches_and_flips_of_corrected_ticks_only() {
        // switches: 2→4, 4→2, 2→4, 3→5; flips: 2,4,2 and 4,2,4
        let levels = [0, 2, 4, 2, 4, 4, 0, 3, 5, 0, 5, 0, 5].map(|l| (l > 0).then_some(l));
        assert_eq!(
            LevelSwitches::count(&levels),
            LevelSwitches {
                switches: 4,
                flips: 2
            }
        );
        assert_eq!(LevelSwitches::count(&[]), LevelSwitches::default());
        assert_eq!(
            LevelSwitches::count(&[Some(3); 10]),
            LevelSwitches::default()
        );
        assert_eq!(LevelSwitches::count(&[None; 10]), LevelSwitches::default());
    }
}
