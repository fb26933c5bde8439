//! Robot model, state and kinematics.
