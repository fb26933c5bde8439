//! The whole humanoid control tick on JVRC-1 (n = 38, Table 1 stack): kinematics, references,
//! task linearisation, acceleration box, solve (IKTC or GF) and integration, along the default
//! imitation run (humanoid3d_dance_b, L_KNEE and L_HIP_R narrowed).
//!
//! Criterion reports the mean tick over a sample; afterwards the median and 99th percentile of
//! single ticks over 5 passes of the clip are printed.

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use iktc::limits::{compute_box, AccelerationBox, BoundMethod, JointLimits};
use iktc::model::{Kinematics, Robot, State};
use iktc::motion::RobotReferences;
use iktc::sim::{percentile, ImitateConfig, ImitationController};
use iktc::solver::{Method, SolveReport, Solver};
use iktc::task::{
    Axes, ComTask, FrameReference, FrameTask, JointTask, Task, TaskEquation, TaskStack,
};
use nalgebra::{DVector, Isometry3, Translation3, UnitQuaternion, Vector6};

#[path = "common/walking.rs"]
mod walking_common;
use walking_common::{feed_plants, imitation_setup as setup, walking_setup};

/// The imitation tick as it was written before [`iktc::Controller`]: kinematics, task stack,
/// box and solver driven by hand, references set by matching level indices. Built from an
/// [`ImitationController`]'s public data (state, limits, references, feet, pelvis) so that both
/// paths compute the same ticks; benched beside it in one run.
#[derive(Clone)]
struct ByHand {
    method: Method,
    refs: RobotReferences,
    limits: JointLimits,
    stack: TaskStack,
    eqs: Vec<TaskEquation>,
    solver: Solver,
    bx: AccelerationBox,
    state: State,
    kin: Kinematics,
    qdd: DVector<f64>,
    pos: Vec<f64>,
    upper: [Vec<f64>; 3],
    pelvis0: Isometry3<f64>,
    im: ImitationController,
}

impl ByHand {
    fn new(robot: &Robot, im: &ImitationController, cfg: &ImitateConfig) -> Self {
        let g = cfg.gains;
        let state = im.state().clone();
        let mut stack = TaskStack::default();
        let mut feet = Vec::new();
        for (f, pose) in cfg.feet.iter().zip(im.feet0()) {
            let mut t = FrameTask::new(robot, f, Axes::ALL, g).unwrap();
            t.set_reference(FrameReference::hold(*pose)).unwrap();
            feet.push(Task::Frame(t));
        }
        stack.push("feet", feet);
        let mut com = ComTask::new(robot, [true, true, false], g).unwrap();
        com.set_reference(im.com_reference_at(0.0)).unwrap();
        stack.push("com", vec![Task::Com(com)]);
        let att = FrameTask::new(robot, &cfg.pelvis, Axes::ORIENTATION, g).unwrap();
        stack.push("att", vec![Task::Frame(att)]);
        let z = FrameTask::new(robot, &cfg.pelvis, Axes::Z, g).unwrap();
        stack.push("z", vec![Task::Frame(z)]);
        let refs = im.references().clone();
        let names: Vec<&str> = refs.joint_names.iter().map(|s| s.as_str()).collect();
        stack.push(
            "upper",
            vec![Task::Joint(JointTask::new(robot, &names, g).unwrap())],
        );
        let eqs = stack.equations(robot);
        let dims: Vec<usize> = eqs.iter().map(|e| e.dim()).collect();
        let m = names.len();
        Self {
            method: cfg.method,
            limits: im.limits().clone(),
            solver: Solver::new(robot.nv(), &dims, cfg.solver).unwrap(),
            stack,
            eqs,
            bx: AccelerationBox::new(robot.nv()),
            kin: Kinematics::new(robot, &state).unwrap(),
            state,
            qdd: DVector::zeros(robot.nv()),
            pos: vec![0.0; robot.nv()],
            upper: [vec![0.0; m], vec![0.0; m], vec![0.0; m]],
            pelvis0: *im.pelvis0(),
            refs,
            im: im.clone(),
        }
    }

    fn tick(&mut self, robot: &Robot, k: usize) -> iktc::Result<&SolveReport> {
        self.kin.update(robot, &self.state)?;
        let r = &self.refs;
        let attitude = r.attitude[k] * self.pelvis0.rotation;
        let (w, wd) = (r.angular_velocity[k], r.angular_acceleration[k]);
        let z = self.pelvis0.translation.z + r.height.position[k];
        let (zd, zdd) = (r.height.velocity[k], r.height.acceleration[k]);
        for (i, t) in r.joints.iter().enumerate() {
            self.upper[0][i] = t.position[k];
            self.upper[1][i] = t.velocity[k];
            self.upper[2][i] = t.acceleration[k];
        }
        let com = self.im.com_reference_at(k as f64 * 0.005);
        for (li, level) in self.stack.levels.iter_mut().enumerate() {
            for task in level.tasks.iter_mut() {
                match (li, task) {
                    (1, Task::Com(c)) => c.set_reference(com)?,
                    (2, Task::Frame(f)) => f.set_reference(FrameReference {
                        pose: Isometry3::from_parts(self.pelvis0.translation, attitude),
                        velocity: Vector6::new(0.0, 0.0, 0.0, w.x, w.y, w.z),
                        acceleration: Vector6::new(0.0, 0.0, 0.0, wd.x, wd.y, wd.z),
                    })?,
                    (3, Task::Frame(f)) => f.set_reference(FrameReference {
                        pose: Isometry3::from_parts(
                            Translation3::new(
                                self.pelvis0.translation.x,
                                self.pelvis0.translation.y,
                                z,
                            ),
                            UnitQuaternion::identity(),
                        ),
                        velocity: Vector6::new(0.0, 0.0, zd, 0.0, 0.0, 0.0),
                        acceleration: Vector6::new(0.0, 0.0, zdd, 0.0, 0.0, 0.0),
                    })?,
                    (4, Task::Joint(j)) => {
                        j.set_reference(&self.upper[0], &self.upper[1], &self.upper[2])?
                    }
                    _ => {}
                }
            }
        }
        self.stack
            .linearize(robot, &self.kin, &self.state, &mut self.eqs)?;
        self.state.dof_positions(robot, &mut self.pos)?;
        compute_box(
            &self.limits,
            &BoundMethod::viable(),
            &self.pos,
            self.state.qd.as_slice(),
            0.005,
            &mut self.bx,
        )?;
        self.solver
            .solve(self.method, &self.eqs, &self.bx, &mut self.qdd)
    }

    fn integrate(&mut self, robot: &Robot) -> iktc::Result<()> {
        self.state.integrate(robot, &self.qdd, 0.005)
    }
}

/// One tick of either path.
trait Tick: Clone {
    fn tick_once(&mut self, robot: &Robot, k: usize) -> usize;
}

impl Tick for ImitationController {
    fn tick_once(&mut self, robot: &Robot, k: usize) -> usize {
        let q = self.tick(robot, k).map(|r| r.qp_solves).unwrap_or(0);
        let _ = self.integrate(robot);
        q
    }
}

impl Tick for ByHand {
    fn tick_once(&mut self, robot: &Robot, k: usize) -> usize {
        let q = self.tick(robot, k).map(|r| r.qp_solves).unwrap_or(0);
        let _ = self.integrate(robot);
        q
    }
}

fn timed<T: Tick>(initial: &T, robot: &Robot, n: usize, iters: u64) -> Duration {
    let mut ctl = initial.clone();
    let mut k = 0;
    let mut total = Duration::ZERO;
    for _ in 0..iters {
        if k == n {
            ctl = initial.clone();
            k = 0;
        }
        let start = Instant::now();
        std::hint::black_box(ctl.tick_once(robot, k));
        total += start.elapsed();
        k += 1;
    }
    total
}

fn bench(c: &mut Criterion) {
    let (robot, refs) = setup();
    let n = refs.len();
    let mut group = c.benchmark_group("humanoid_tick");
    for (name, method) in [("iktc", Method::Iktc), ("gf", Method::Cascade)] {
        let cfg = ImitateConfig {
            method,
            ..ImitateConfig::default()
        };
        let initial = ImitationController::new(&robot, &refs, &cfg).expect("controller");
        let by_hand = ByHand::new(&robot, &initial, &cfg);
        // Both paths compute the same ticks.
        {
            let (mut a, mut b) = (initial.clone(), by_hand.clone());
            for k in 0..n {
                a.tick_once(&robot, k);
                b.tick_once(&robot, k);
                assert_eq!(a.qdd(), &b.qdd, "{name} tick {k}: the paths differ");
            }
        }
        group.bench_function(name, |b| {
            b.iter_custom(|iters| timed(&initial, &robot, n, iters))
        });
        group.bench_function(format!("{name}_by_hand"), |b| {
            b.iter_custom(|iters| timed(&by_hand, &robot, n, iters))
        });
        // Interleaved passes over the clip, each path in turn: the ratio of the medians.
        let (mut pa, mut pb) = (Vec::new(), Vec::new());
        for _ in 0..10 {
            pa.push(timed(&initial, &robot, n, n as u64).as_secs_f64());
            pb.push(timed(&by_hand, &robot, n, n as u64).as_secs_f64());
        }
        let (ma, mb) = (percentile(&pa, 0.5), percentile(&pb, 0.5));
        eprintln!(
            "humanoid_tick/{name}: Controller {:.2} µs, by hand {:.2} µs per tick (median of 10 interleaved passes): ratio Controller / by hand = {:.3}",
            ma * 1e6 / n as f64,
            mb * 1e6 / n as f64,
            ma / mb
        );
        // Single-tick distribution.
        let mut ticks = Vec::with_capacity(5 * n);
        for _ in 0..5 {
            let mut ctl = initial.clone();
            for k in 0..n {
                let start = Instant::now();
                let _ = std::hint::black_box(ctl.tick(&robot, k).map(|r| r.qp_solves));
                let _ = ctl.integrate(&robot);
                ticks.push(start.elapsed().as_secs_f64() * 1e6);
            }
        }
        eprintln!(
            "humanoid_tick/{name}: single ticks over 5 passes of {n}: median {:.1} µs, p99 {:.1} µs, max {:.1} µs",
            percentile(&ticks, 0.5),
            percentile(&ticks, 0.99),
            percentile(&ticks, 1.0)
        );
    }
    group.finish();
}

/// The walking tick (issue 6): walking pattern, damping controller and IK, with the ZMP of the
/// simulated compliant robot fed back (the plant's step is outside the timed region).
fn bench_walk(c: &mut Criterion) {
    use iktc::balance::SimPlant;
    use iktc::sim::WalkingController;
    let (robot, refs) = setup();
    let (initial, plants0) = walking_setup(&robot, &refs);
    let n = initial.ticks();
    // One pass: returns the time of each tick [µs].
    let pass = |wc: &mut WalkingController,
                plants: &mut [SimPlant; 2],
                ticks: &mut Vec<f64>,
                k: usize|
     -> Duration {
        let dev = [plants[0].measure(), plants[1].measure()];
        let start = Instant::now();
        let wt = std::hint::black_box(wc.tick(&robot, k, dev)).expect("tick");
        let _ = wc.integrate(&robot);
        let el = start.elapsed();
        ticks.push(el.as_secs_f64() * 1e6);
        feed_plants(wc, &wt, plants);
        el
    };
    c.bench_function("humanoid_tick/walking_iktc", |b| {
        b.iter_custom(|iters| {
            let (mut wc, mut plants) = (initial.clone(), plants0.clone());
            let mut scratch = Vec::new();
            let mut k = 0;
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                if k == n {
                    wc = initial.clone();
                    plants = plants0.clone();
                    k = 0;
                }
                scratch.clear();
                total += pass(&mut wc, &mut plants, &mut scratch, k);
                k += 1;
            }
            total
        })
    });
    let mut ticks = Vec::with_capacity(3 * n);
    for _ in 0..3 {
        let (mut wc, mut plants) = (initial.clone(), plants0.clone());
        for k in 0..n {
            pass(&mut wc, &mut plants, &mut ticks, k);
        }
    }
    eprintln!(
        "humanoid_tick/walking_iktc: single ticks over 3 passes of {n}: median {:.1} µs, p99 {:.1} µs, max {:.1} µs",
        percentile(&ticks, 0.5),
        percentile(&ticks, 0.99),
        percentile(&ticks, 1.0)
    );
}

criterion_group!(benches, bench, bench_walk);
criterion_main!(benches);
