//! Full kinematics of JVRC-1: all link poses, the Jacobians and drifts of both feet and the
//! pelvis, the COM with its Jacobian and drift (target ≤ 5 µs median).

use criterion::{criterion_group, criterion_main, Criterion};
use iktc::model::*;
use nalgebra::DMatrix;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let mut s = State::neutral(&robot);
    for k in 0..robot.nv() {
        s.qd[k] = 0.1 * (k as f64).sin();
    }
    let mut kin = Kinematics::new(&robot, &s).unwrap();
    let frames = [
        robot.frame_id("r_ankle").unwrap(),
        robot.frame_id("l_ankle").unwrap(),
        robot.frame_id("PELVIS_S").unwrap(),
    ];
    let mut j = [
        DMatrix::zeros(6, robot.nv()),
        DMatrix::zeros(6, robot.nv()),
        DMatrix::zeros(6, robot.nv()),
    ];
    let mut jc = DMatrix::zeros(3, robot.nv());
    c.bench_function("jvrc1_full_kinematics", |b| {
        b.iter(|| {
            kin.update(&robot, black_box(&s)).unwrap();
            for (f, jf) in frames.iter().zip(j.iter_mut()) {
                kin.frame_jacobian(&robot, *f, jf).unwrap();
                black_box(kin.frame_drift(&robot, *f).unwrap());
            }
            kin.com_jacobian(&robot, &mut jc).unwrap();
            black_box(kin.com_drift());
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
