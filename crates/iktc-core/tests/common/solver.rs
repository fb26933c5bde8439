//! Random task hierarchies for solver tests and benchmarks.

use iktc_core::limits::AccelerationBox;
use iktc_core::task::TaskEquation;
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

pub fn random_levels(r: &mut ChaCha8Rng, n: usize, dims: &[usize]) -> Vec<TaskEquation> {
    dims.iter()
        .enumerate()
        .map(|(i, &m)| {
            let mut e = TaskEquation::zeros(format!("level{}", i + 1), m, n);
            e.jacobian = DMatrix::from_fn(m, n, |_, _| r.random_range(-1.0..1.0));
            e.rhs = DVector::from_fn(m, |_, _| r.random_range(-5.0..5.0));
            e
        })
        .collect()
}

pub fn wide_box(n: usize) -> AccelerationBox {
    let mut b = AccelerationBox::new(n);
    b.lower.fill(-1e6);
    b.upper.fill(1e6);
    b
}

/// A box around `q` of half-width `w`, with `k` dofs (chosen at random) cut so that `q`
/// violates them by `cut`.
pub fn box_violated_by(
    r: &mut ChaCha8Rng,
    q: &DVector<f64>,
    w: f64,
    k: usize,
    cut: f64,
) -> AccelerationBox {
    let n = q.len();
    let mut b = AccelerationBox::new(n);
    for d in 0..n {
        b.lower[d] = q[d] - w;
        b.upper[d] = q[d] + w;
    }
    for _ in 0..k {
        let d = r.random_range(0..n);
        if r.random_bool(0.5) {
            b.upper[d] = q[d] - cut;
            b.lower[d] = b.lower[d].min(b.upper[d] - w);
        } else {
            b.lower[d] = q[d] + cut;
            b.upper[d] = b.upper[d].max(b.lower[d] + w);
        }
    }
    b
}
