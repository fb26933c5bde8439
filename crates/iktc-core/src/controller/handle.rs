//! Typed handles to the tasks of a [`Controller`](super::Controller).
//!
//! A handle names one task of one controller: the identity of the controller whose builder made
//! it, the task's level and its place in the level. The controller checks the identity on every
//! use, so a handle of another controller is an error ([`Error::ForeignHandle`]), never a silent
//! write into some other task. A clone of a controller has the same tasks in the same places
//! and keeps its identity, so it accepts the handles of its original.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::Error;

/// The identity of a controller (unique in the process; kept by clones).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ControllerId(u64);

static NEXT_ID: AtomicU64 = AtomicU64::new(1);

impl ControllerId {
    /// A fresh identity.
    pub(crate) fn fresh() -> Self {
        Self(NEXT_ID.fetch_add(1, Ordering::Relaxed))
    }

    /// The number behind the identity (for messages).
    pub fn get(&self) -> u64 {
        self.0
    }
}

/// Where a task sits: its controller, its level (0 = highest priority) and its index in the
/// level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct TaskRef {
    pub(crate) owner: ControllerId,
    pub(crate) level: usize,
    pub(crate) index: usize,
}

impl TaskRef {
    /// The error for this handle used with controller `controller`.
    pub(crate) fn foreign(&self, kind: &'static str, controller: ControllerId) -> Error {
        Error::ForeignHandle {
            kind,
            owner: self.owner.get(),
            controller: controller.get(),
        }
    }
}

macro_rules! handle {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub struct $name(pub(crate) TaskRef);

        impl $name {
            /// The level of the task (0-based, 0 = highest priority), as in
            /// [`SolveReport::corrected_from`](crate::solver::SolveReport::corrected_from).
            pub fn level(&self) -> usize {
                self.0.level
            }

            /// The controller this handle belongs to.
            pub fn owner(&self) -> ControllerId {
                self.0.owner
            }
        }
    };
}

handle!(
    /// A frame task ([`FrameTask`](crate::task::FrameTask)) of a controller.
    FrameHandle
);
handle!(
    /// A centre-of-mass task ([`ComTask`](crate::task::ComTask)) of a controller.
    ComHandle
);
handle!(
    /// A joint task ([`JointTask`](crate::task::JointTask)) of a controller.
    JointsHandle
);
