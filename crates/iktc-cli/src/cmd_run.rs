//! `iktc run planar3r`: the 3R experiment of Section 3.3, with its trajectory, summary and
//! figures (Figs. 4–8).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use iktc::limits::BoundMethod;
use iktc::model::JointLimit;
use iktc::resources::RunLimits;
use iktc::sim::{run_planar3r, ArmTask, Planar3rConfig, Planar3rRun, Planar3rStep};
use iktc::solver::Method;
use iktc_report::{write_csv, write_figure, Figure, Panel, Section, Series, Table};

/// Which scenario to run.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum Scenario {
    /// The 3R planar arm of Section 3.3.
    Planar3r,
}

/// Solver choice on the command line.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum SolverArg {
    /// IKTC (Section 3.2).
    Iktc,
    /// The cascade of QPs (Kanoun et al.).
    Gf,
    /// The prioritized solution clamped to the box.
    Clamp,
}

impl SolverArg {
    /// The library's method.
    pub fn method(self) -> Method {
        match self {
            SolverArg::Iktc => Method::Iktc,
            SolverArg::Gf => Method::Cascade,
            SolverArg::Clamp => Method::Clamp,
        }
    }
}

/// Bound choice on the command line.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum BoundsArg {
    /// Eq. (14) as printed (unsafe in discrete time, errata 3.1).
    Paper,
    /// Discrete-time viable bounds (errata 3.1, Del Prete 2018).
    Viable,
    /// Viable bounds with a discrete braking profile: rest on a limit without chatter.
    Quiet,
}

impl BoundsArg {
    /// The library's method.
    pub fn method(self) -> BoundMethod {
        match self {
            BoundsArg::Paper => BoundMethod::Paper,
            BoundsArg::Viable => BoundMethod::viable(),
            BoundsArg::Quiet => BoundMethod::quiet(),
        }
    }
}

/// Arguments of `iktc run`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The scenario.
    #[arg(value_enum)]
    pub scenario: Scenario,
    /// Solver.
    #[arg(long, value_enum, default_value = "iktc")]
    pub solver: SolverArg,
    /// Joint bounds.
    #[arg(long, value_enum, default_value = "quiet")]
    pub bounds: BoundsArg,
    /// Control period \[s\].
    #[arg(long, default_value_t = 0.005)]
    pub dt: f64,
    /// Priority order, highest first: a permutation of Px, Py, theta3.
    #[arg(long, value_delimiter = ',', default_value = "Py,Px,theta3")]
    pub priority: Vec<String>,
    /// Output directory.
    #[arg(long, default_value = "out/planar3r")]
    pub out: PathBuf,
    /// Most control ticks of the run (its duration over --dt).
    #[arg(long, default_value_t = RunLimits::default().max_ticks)]
    pub max_ticks: usize,
}

fn parse_task(s: &str) -> Result<ArmTask> {
    match s.trim().to_ascii_lowercase().as_str() {
        "px" => Ok(ArmTask::Px),
        "py" => Ok(ArmTask::Py),
        "theta3" | "theta" => Ok(ArmTask::Theta),
        other => anyhow::bail!("unknown task `{other}` in --priority: expected Px, Py or theta3"),
    }
}

/// Runs `iktc run`.
pub fn run(a: &Args) -> Result<()> {
    let Scenario::Planar3r = a.scenario;
    if a.priority.len() != 3 {
        anyhow::bail!(
            "--priority needs the three tasks Px, Py, theta3 in some order, got {}",
            a.priority.len()
        );
    }
    let cfg = Planar3rConfig {
        method: a.solver.method(),
        bounds: a.bounds.method(),
        dt: RunLimits::default().check_dt("--dt", a.dt)?,
        run_limits: RunLimits {
            max_ticks: a.max_ticks,
            ..RunLimits::default()
        },
        priority: [
            parse_task(&a.priority[0])?,
            parse_task(&a.priority[1])?,
            parse_task(&a.priority[2])?,
        ],
        ..Default::default()
    };
    let r = run_planar3r(&cfg)?;
    let files = write_run(&r, &a.out)?;
    let s = &r.summary;
    crate::outln!(
        "3R arm, {} with {} bounds, Δt = {} s: worst position margin {:+.3e} rad, velocity {:+.3e} rad/s, acceleration {:+.3e} rad/s²",
        s.solver, s.bounds, s.dt, s.worst_position_margin, s.worst_velocity_margin, s.worst_acceleration_margin
    )?;
    crate::outln!(
        "final errors Px {:+.2e} m, Py {:+.2e} m, theta3 {:+.2} deg; q1 min {:.3} deg; QPs/step ≤ {}; median tick {:.1} µs",
        s.final_error[0], s.final_error[1], s.final_error[2].to_degrees(), s.min_q1.to_degrees(), s.qp_per_step_max, s.tick_median_us
    )?;
    crate::outln!("wrote {} files to {}", files.len() + 2, a.out.display())?;
    Ok(())
}

const DEG: f64 = 180.0 / std::f64::consts::PI;

/// Writes trajectory.csv, summary.json and the figures of one run; returns the figures
/// (path relative to `dir`, caption).
pub fn write_run(r: &Planar3rRun, dir: &Path) -> Result<Vec<(String, String)>> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    write_csv(
        &dir.join("trajectory.csv"),
        &trajectory_header(),
        &trajectory_rows(r),
    )?;
    std::fs::write(
        dir.join("summary.json"),
        crate::finite::to_json("summary.json", &r.summary)?,
    )?;
    let tag = format!(
        "{} / {} bounds",
        r.summary.solver.to_uppercase(),
        r.summary.bounds
    );
    let t: Vec<f64> = r.steps.iter().map(|s| s.t).collect();
    let mut figs = Vec::new();
    write_figure(&motion_figure(r, &tag), dir, "fig4_motion")?;
    figs.push((
        "fig4_motion.svg".to_string(),
        format!("Fig. 4: arm motion and desired tip path ({tag})"),
    ));
    // Figs. 5–7: q, q̇, q̈ of each joint with limits.
    let robot = iktc::model::planar3r();
    for (j, lim) in robot.dof_limits().iter().enumerate() {
        let stem = format!("fig{}_q{}", 5 + j, j + 1);
        write_figure(&joint_figure(r, &t, j, lim, &tag), dir, &stem)?;
        figs.push((
            format!("{stem}.svg"),
            format!(
                "Fig. {}: position, velocity and acceleration of q{} with their limits and the acceleration box ({tag})",
                5 + j,
                j + 1
            ),
        ));
    }
    write_figure(&errors_figure(r, &t, &tag), dir, "fig8_errors")?;
    figs.push((
        "fig8_errors.svg".to_string(),
        format!("Fig. 8: task errors ({tag})"),
    ));
    Ok(figs)
}

/// The column names of trajectory.csv: time, the joints' motion and acceleration box, each
/// task's reference, value, error and correction, and the tick's cost.
fn trajectory_header() -> Vec<String> {
    let mut header: Vec<String> = vec!["t".into()];
    for p in ["q", "qd", "qdd", "box_lower", "box_upper"] {
        for j in 1..=3 {
            header.push(format!("{p}{j}"));
        }
    }
    for p in ["ref", "value", "error", "correction"] {
        for t in ["Px", "Py", "theta3"] {
            header.push(format!("{p}_{t}"));
        }
    }
    header.extend(
        [
            "corrected_from_level",
            "qp_solves",
            "empty_box_dofs",
            "tick_us",
        ]
        .map(String::from),
    );
    header
}

/// The rows of trajectory.csv, one per tick, in the order of [`trajectory_header`].
fn trajectory_rows(r: &Planar3rRun) -> Vec<Vec<f64>> {
    r.steps
        .iter()
        .map(|s| {
            let mut v = vec![s.t];
            for a in [
                s.q,
                s.qd,
                s.qdd,
                s.box_lower,
                s.box_upper,
                s.reference,
                s.value,
                s.error,
                s.correction,
            ] {
                v.extend(a);
            }
            v.extend([
                crate::columns::level_number(s.corrected_from),
                s.qp_solves as f64,
                s.empty_dofs as f64,
                s.tick_us,
            ]);
            v
        })
        .collect()
}

/// Fig. 4: the arm's motion (every 0.1 s) and the desired tip path [m].
fn motion_figure(r: &Planar3rRun, tag: &str) -> Figure {
    let mut p = Panel::new(format!("3R arm motion ({tag})"), "x [m]", "y [m]").equal_aspect();
    let stride = (r.steps.len() / 12).max(1);
    for (k, s) in r.steps.iter().enumerate().step_by(stride) {
        let (a, b, c) = (s.q[0], s.q[0] + s.q[1], s.q[0] + s.q[1] + s.q[2]);
        let xs = vec![0.0, a.cos(), a.cos() + b.cos(), a.cos() + b.cos() + c.cos()];
        let ys = vec![0.0, a.sin(), a.sin() + b.sin(), a.sin() + b.sin() + c.sin()];
        let label = if k == 0 {
            "arm (every 0.1 s)".to_string()
        } else {
            String::new()
        };
        p = p.with(Series::line(label, xs, ys));
    }
    p = p
        .with(Series::points(
            "desired tip path",
            r.steps.iter().map(|s| s.reference[0]).collect(),
            r.steps.iter().map(|s| s.reference[1]).collect(),
        ))
        .with(Series::dashed(
            "tip path",
            r.steps.iter().map(|s| s.value[0]).collect(),
            r.steps.iter().map(|s| s.value[1]).collect(),
        ));
    Figure::new(format!("Fig. 4 — tracking under joint limits ({tag})"))
        .panel(p)
        .panel_size(700, 560)
}

/// Figs. 5–7: position [deg], velocity [deg/s] and acceleration [deg/s²] of joint `j` with its
/// limits `lim` and the acceleration box.
fn joint_figure(r: &Planar3rRun, t: &[f64], j: usize, lim: &JointLimit, tag: &str) -> Figure {
    let col =
        |f: &dyn Fn(&iktc::sim::Planar3rStep) -> f64| r.steps.iter().map(f).collect::<Vec<f64>>();
    Figure::new(format!("Fig. {} — joint q{} ({tag})", 5 + j, j + 1))
        .panel(
            Panel::new(format!("q{}", j + 1), "t [s]", "q [deg]")
                .with(Series::line(
                    format!("q{}", j + 1),
                    t.to_vec(),
                    col(&|s| s.q[j] * DEG),
                ))
                .hline(lim.lower * DEG, "lower limit")
                .hline(lim.upper * DEG, "upper limit"),
        )
        .panel(
            Panel::new(format!("velocity dq{}/dt", j + 1), "t [s]", "dq/dt [deg/s]")
                .with(Series::line(
                    format!("dq{}/dt", j + 1),
                    t.to_vec(),
                    col(&|s| s.qd[j] * DEG),
                ))
                .hline(lim.velocity * DEG, "+v_max")
                .hline(-lim.velocity * DEG, "−v_max"),
        )
        .panel(
            Panel::new(
                format!("acceleration d²q{}/dt²", j + 1),
                "t [s]",
                "d²q/dt² [deg/s²]",
            )
            .with(Series::line(
                format!("d²q{}/dt²", j + 1),
                t.to_vec(),
                col(&|s| s.qdd[j] * DEG),
            ))
            .with(Series::dashed(
                "box lower b_l",
                t.to_vec(),
                col(&|s| s.box_lower[j].max(-3.0 * lim.acceleration) * DEG),
            ))
            .with(Series::dashed(
                "box upper b_u",
                t.to_vec(),
                col(&|s| s.box_upper[j].min(3.0 * lim.acceleration) * DEG),
            ))
            .hline(lim.acceleration * DEG, "+a_max")
            .hline(-lim.acceleration * DEG, "−a_max"),
        )
}

/// Fig. 8: the task errors (Px, Py [m], θ3 [deg]).
fn errors_figure(r: &Planar3rRun, t: &[f64], tag: &str) -> Figure {
    let mut fig = Figure::new(format!("Fig. 8 — task errors ({tag})"));
    for (k, (name, unit, scale)) in [("Px", "m", 1.0), ("Py", "m", 1.0), ("θ3", "deg", DEG)]
        .iter()
        .enumerate()
    {
        fig = fig.panel(
            Panel::new(
                format!("error of {name}"),
                "t [s]",
                format!("{name} error [{unit}]"),
            )
            .with(Series::line(
                format!("{name}_d − {name}"),
                t.to_vec(),
                r.steps.iter().map(|s| s.error[k] * scale).collect(),
            )),
        );
    }
    fig
}

/// One row of the summary table (margins in rad, rad/s, rad/s²; angles in deg; errors in m;
/// jerk in rad/s³; tick times in µs).
fn summary_row(name: &str, r: &Planar3rRun) -> Vec<String> {
    let s = &r.summary;
    vec![
        name.into(),
        format!("{:+.2e}", s.worst_position_margin),
        format!("{:+.2e}", s.worst_velocity_margin),
        format!("{:+.2e}", s.worst_acceleration_margin),
        s.empty_box_steps.to_string(),
        format!("{:.3}", s.min_q1.to_degrees()),
        format!("{:.1e} / {:.1e}", s.final_error[0], s.final_error[1]),
        format!("{:.2}", s.final_error[2].to_degrees()),
        format!("{:.2} / {}", s.qp_per_step_mean, s.qp_per_step_max),
        format!("{} / {}", s.corrected_steps, s.climbed_steps),
        s.smoothness_settled
            .iter()
            .map(|j| format!("{:.2e}", j.smoothness.qdd_std.to_degrees()))
            .collect::<Vec<_>>()
            .join(" / "),
        s.smoothness
            .iter()
            .map(|j| {
                format!(
                    "{:.0} ({:.0} %)",
                    j.smoothness.rms_jerk,
                    100.0 * j.smoothness.reversal_share
                )
            })
            .collect::<Vec<_>>()
            .join(" / "),
        format!("{:.1}", s.tick_median_us),
    ]
}

/// The section's introduction (HTML).
const INTRO: &str = "<p>Three prioritized tasks on the tip of a planar 3R arm with unit links: 1 = P<sub>y</sub>, 2 = P<sub>x</sub>, \
         3 = θ<sub>3</sub> (errata 2.1). P<sub>x</sub> moves from 1 to 2 in one second; q<sub>1</sub> reaches its 60° lower limit \
         near P<sub>x</sub> ≈ 1.48 and the three tasks become incompatible, so the lowest, θ<sub>3</sub>, is sacrificed. \
         Margins are signed: positive means a limit was exceeded (in-step peaks included). \
         With the viable bounds q1 never settles on its limit: it brakes at a_stop, turns round inside the last step, is pushed back, \
         and q̈ alternates between about ±a_stop tick by tick for the rest of the run. The quiet bounds brake along a discrete profile \
         that ends at rest at a tick, and q1 stays on 60° with q̈ = 0 (jerk = (q̈<sub>k</sub> − q̈<sub>k−1</sub>)/Δt).</p>";

/// The empty summary table with its header.
fn summary_table() -> Table {
    Table::new(
        "Summaries (margins in rad, rad/s, rad/s²; errors at t = 2 s)",
        [
            "run",
            "position margin",
            "velocity margin",
            "accel. margin",
            "empty-box steps",
            "min q1 [deg]",
            "final Px / Py error [m]",
            "final θ3 error [deg]",
            "QPs per step (mean / max)",
            "corrected / climbed steps",
            "std of q̈ from 0.7 s, q1 / q2 / q3 [deg/s²]",
            "RMS jerk [rad/s³] (ticks where q̈'s change reverses), q1 / q2 / q3",
            "median tick [µs]",
        ]
        .map(String::from)
        .to_vec(),
    )
}

/// Runs the 3R experiment with IKTC, GF and clamp (viable bounds), IKTC with the paper's
/// bound and IKTC and GF with the quiet bounds, writes everything under `out/planar3r`, and returns the report section.
pub fn planar3r_section(out: &Path) -> Result<Section> {
    let base = out.join("planar3r");
    let configs = [
        ("iktc_viable", Method::Iktc, BoundMethod::viable()),
        ("gf_viable", Method::Cascade, BoundMethod::viable()),
        ("clamp_viable", Method::Clamp, BoundMethod::viable()),
        ("iktc_paper", Method::Iktc, BoundMethod::Paper),
        ("iktc_quiet", Method::Iktc, BoundMethod::quiet()),
        ("gf_quiet", Method::Cascade, BoundMethod::quiet()),
    ];
    let mut sec = Section::new("The 3R planar arm (Section 3.3)").intro(INTRO);
    let mut table = summary_table();
    let mut runs = Vec::new();
    for (name, method, bounds) in configs {
        let r = run_planar3r(&Planar3rConfig {
            method,
            bounds,
            ..Default::default()
        })?;
        let figs = write_run(&r, &base.join(name))?;
        table = table.row(summary_row(name, &r));
        sec = add_run(sec, name, figs);
        runs.push(r);
    }
    // IKTC vs GF, and the paper's bound vs the viable bound.
    write_figure(&comparison_figure(&runs), &base, "iktc_vs_gf")?;
    sec = sec.figure(
        "planar3r/iktc_vs_gf.svg",
        "IKTC, GF and clamping: q1, θ3 error and Px error",
    );
    write_figure(&bounds_figure(&runs), &base, "paper_vs_viable")?;
    sec = sec.figure(
        "planar3r/paper_vs_viable.svg",
        "q1 and q̈1 under the paper's bound and the viable bound: eq. (14) lets q1 pass 60°",
    );
    Ok(sec.table(table))
}

/// `sec` with the figures of run `name` (`iktc_viable`'s only) and the links to its files.
fn add_run(mut sec: Section, name: &str, figs: Vec<(String, String)>) -> Section {
    if name == "iktc_viable" {
        for (f, c) in figs {
            sec = sec.figure(format!("planar3r/{name}/{f}"), c);
        }
    }
    sec = sec.link(
        format!("planar3r/{name}/summary.json"),
        format!("{name}: summary.json"),
    );
    sec.link(
        format!("planar3r/{name}/trajectory.csv"),
        format!("{name}: trajectory.csv"),
    )
}

/// The times [s] of the first run and the column `f` of run `i`.
fn run_col(runs: &[Planar3rRun], i: usize, f: &dyn Fn(&Planar3rStep) -> f64) -> Vec<f64> {
    runs[i].steps.iter().map(f).collect()
}

/// IKTC, GF and clamping with the viable bounds (runs 0, 1, 2): q1 [deg], θ3 error [deg] and
/// Px error [m].
fn comparison_figure(runs: &[Planar3rRun]) -> Figure {
    let t = run_col(runs, 0, &|s| s.t);
    let get = |i: usize, f: &dyn Fn(&Planar3rStep) -> f64| run_col(runs, i, f);
    Figure::new("IKTC and GF side by side (viable bounds)")
        .panel(
            Panel::new("q1", "t [s]", "q1 [deg]")
                .with(Series::line("IKTC", t.clone(), get(0, &|s| s.q[0] * DEG)))
                .with(Series::dashed("GF", t.clone(), get(1, &|s| s.q[0] * DEG)))
                .with(Series::dashed(
                    "clamp",
                    t.clone(),
                    get(2, &|s| s.q[0] * DEG),
                ))
                .hline(60.0, "q1 lower limit"),
        )
        .panel(
            Panel::new("θ3 error", "t [s]", "θ3 error [deg]")
                .with(Series::line(
                    "IKTC",
                    t.clone(),
                    get(0, &|s| s.error[2] * DEG),
                ))
                .with(Series::dashed(
                    "GF",
                    t.clone(),
                    get(1, &|s| s.error[2] * DEG),
                ))
                .with(Series::dashed(
                    "clamp",
                    t.clone(),
                    get(2, &|s| s.error[2] * DEG),
                )),
        )
        .panel(
            Panel::new("P_x error", "t [s]", "Px error [m]")
                .with(Series::line("IKTC", t.clone(), get(0, &|s| s.error[0])))
                .with(Series::dashed("GF", t.clone(), get(1, &|s| s.error[0])))
                .with(Series::dashed("clamp", t.clone(), get(2, &|s| s.error[0]))),
        )
}

/// The paper's bound (run 3) against the viable bound (run 0) under IKTC: q1 [deg] and its
/// acceleration [deg/s²].
fn bounds_figure(runs: &[Planar3rRun]) -> Figure {
    let t = run_col(runs, 0, &|s| s.t);
    let get = |i: usize, f: &dyn Fn(&Planar3rStep) -> f64| run_col(runs, i, f);
    Figure::new("The paper's bound (eq. 14) against the viable bound, IKTC")
        .panel(
            Panel::new("q1 near its lower limit", "t [s]", "q1 [deg]")
                .with(Series::line("viable", t.clone(), get(0, &|s| s.q[0] * DEG)))
                .with(Series::dashed(
                    "paper eq. (14)",
                    t.clone(),
                    get(3, &|s| s.q[0] * DEG),
                ))
                .hline(60.0, "q1 lower limit"),
        )
        .panel(
            Panel::new("acceleration of q1", "t [s]", "d²q1/dt² [deg/s²]")
                .with(Series::line(
                    "viable",
                    t.clone(),
                    get(0, &|s| s.qdd[0] * DEG),
                ))
                .with(Series::dashed(
                    "paper eq. (14)",
                    t.clone(),
                    get(3, &|s| s.qdd[0] * DEG),
                ))
                .hline(1800.0, "+a_max")
                .hline(-1800.0, "−a_max"),
        )
}
