//! `iktc balance`: the damping-controller scenarios of Section 4 (identify, design, push).
//! Argument parsing and output files only; the scenarios live in `iktc::balance::scenario`.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::{Args, Subcommand, ValueEnum};
use iktc::balance::{
    run_design, run_identify, run_push, DesignResult, DesignScenario, IdentifyResult,
    IdentifyScenario, PushResult, PushScenario, SupportPhase,
};
use iktc_report::{write_csv, write_figure, Figure, Panel, Section, Series, Table};
use serde::Serialize;

/// Arguments of `iktc balance`.
#[derive(Args)]
pub struct BalanceArgs {
    #[command(subcommand)]
    command: BalanceCommand,
}

#[derive(Subcommand)]
enum BalanceCommand {
    /// Sine sweep on the simulated plant, Bode plot with the fitted model (Fig. 12).
    Identify {
        /// Output directory.
        #[arg(long, default_value = "out/balance")]
        out: PathBuf,
        /// Seed of the sensor noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Pole placement: gain, closed-loop poles, root locus (Fig. 13).
    Design {
        /// Output directory.
        #[arg(long, default_value = "out/balance")]
        out: PathBuf,
    },
    /// ZMP after a push on the COM with and without the controller (Figs. 16–17).
    Push {
        /// Support phase.
        #[arg(long, value_enum, default_value_t = Phase::Dsp)]
        phase: Phase,
        /// Output directory.
        #[arg(long, default_value = "out/balance")]
        out: PathBuf,
        /// Seed of the sensor noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Phase {
    /// Single support.
    Ssp,
    /// Double support.
    Dsp,
}

impl Phase {
    fn support(self) -> SupportPhase {
        match self {
            Phase::Ssp => SupportPhase::Single,
            Phase::Dsp => SupportPhase::Double,
        }
    }
    fn name(self) -> &'static str {
        match self {
            Phase::Ssp => "ssp",
            Phase::Dsp => "dsp",
        }
    }
}

/// Runs `iktc balance …`.
pub fn run(args: BalanceArgs) -> anyhow::Result<()> {
    match args.command {
        BalanceCommand::Identify { out, seed } => {
            let r = identify(&out, seed)?;
            for c in &r.comparison {
                crate::outln!(
                    "{:<32} true {:>10.5}  identified {:>10.5} ± {:.5} {}  ({:+.2} %)",
                    c.name,
                    c.true_value,
                    c.identified,
                    c.std_error,
                    c.unit,
                    100.0 * c.relative_error
                )?;
            }
            crate::outln!(
                "RMS fit error: {:.2} dB, {:.2} deg -> {}",
                r.identification.rms_magnitude_error_db,
                r.identification.rms_phase_error_deg,
                out.join("identify").display()
            )?;
        }
        BalanceCommand::Design { out } => {
            let r = design(&out)?;
            crate::outln!(
                "K_f = [{:.6}, {:.6}], N = {:.6}; closed-loop IPCJ poles {:.5} ± {:.5}j -> {}",
                r.continuous.gain[0],
                r.continuous.gain[1],
                r.continuous.feedforward,
                r.continuous.closed_loop_poles[0][0],
                r.continuous.closed_loop_poles[0][1],
                out.join("design").display()
            )?;
        }
        BalanceCommand::Push { phase, out, seed } => {
            let r = push(&out, phase, seed)?;
            for m in &r.metrics {
                crate::outln!(
                    "{:?}: peak {:.1} -> {:.1} mm, settling {} -> {} s, ζ {:.3} -> {:.3} (designed {:.2}), static gain {:.4} / {:.4} m/rad",
                    m.plane,
                    1e3 * m.open.peak,
                    1e3 * m.closed.peak,
                    fmt_opt(m.open.settling_time),
                    fmt_opt(m.closed.settling_time),
                    m.open.damping_ratio,
                    m.closed.damping_ratio,
                    m.designed_damping_ratio,
                    m.static_gain_open,
                    m.static_gain_closed
                )?;
            }
            crate::outln!(
                "ZMP outside the support polygon by at most {:.4} m without the controller, {:.4} m with it; {}",
                r.zmp_excursion_open,
                r.zmp_excursion_closed,
                crate::scenario::health_text(&r.health)
            )?;
            crate::outln!(
                "-> {}",
                out.join(format!("push-{}", phase.name())).display()
            )?;
        }
    }
    Ok(())
}

/// Runs the three scenarios (push in both phases) into `out_dir/balance` and returns the
/// report section; paths in it are relative to `out_dir`.
pub fn balance_section(out_dir: &Path) -> anyhow::Result<Section> {
    let dir = out_dir.join("balance");
    let id = identify(&dir, 1)?;
    let de = design(&dir)?;
    let pushes = [
        (Phase::Dsp, push(&dir, Phase::Dsp, 1)?),
        (Phase::Ssp, push(&dir, Phase::Ssp, 1)?),
    ];
    let mut s = Section::new("Damping controller (Section 4)").intro(
        "<p>The ZMP damping controller on the inverted pendulum with a compliant joint (IPCJ), \
         with the errata's corrected model (27), (31)–(33). A synthetic robot (l = 0.8 m, \
         45 kg, τ<sub>s</sub> = 20 ms, true delay 20 ms, 0.5 mm ZMP noise) stands in for Hubo. \
         <b>Identify</b>: a sine sweep at 200 Hz, fitted by Levenberg–Marquardt (Fig. 12). \
         <b>Design</b>: pole placement to ζ = 0.72, keeping the lag and Padé poles (Fig. 13). \
         <b>Push</b>: a 2 N·s impulse on the COM, with and without the controller \
         (Figs. 16–17); the damping ratio is fitted to the ZMP response.</p>",
    );
    s = s
        .figure(
            "balance/identify/bode.svg",
            "Fig. 12: Bode plot of y_ZMP/u, ỹz̃ plane in DSP: measured (sine sweep on the \
             simulated plant with a true delay), fitted model (31), true model.",
        )
        .figure(
            "balance/design/root_locus.svg",
            "Fig. 13: root locus of the identified IPCJ system under output feedback, and the \
             path of the pole placement to ζ = 0.72.",
        );
    for (p, _) in &pushes {
        let name = p.name();
        s = s.figure(
            format!("balance/push-{name}/zmp.svg"),
            format!(
                "Figs. 16–17: ZMP after a push in {}, with and without the damping controller, \
                 and the controller's COM offset Δc.",
                name.to_uppercase()
            ),
        );
    }
    let mut t = Table::new(
        "Identification: true against identified parameters",
        vec![
            "parameter".into(),
            "unit".into(),
            "true".into(),
            "identified".into(),
            "std. error".into(),
            "error [%]".into(),
        ],
    );
    for c in &id.comparison {
        t = t.row(vec![
            c.name.clone(),
            c.unit.clone(),
            format!("{:.5}", c.true_value),
            format!("{:.5}", c.identified),
            format!("{:.5}", c.std_error),
            format!("{:+.2}", 100.0 * c.relative_error),
        ]);
    }
    s = s.table(t);
    let cd = &de.continuous;
    let pole = |p: [f64; 2]| format!("{:.4} {:+.4}j", p[0], p[1]);
    s = s.table(
        Table::new(
            "Design (ỹz̃-DSP case; errata 2.2 reference: K_f = [0, 0.098950], poles −9.04779 ± 8.72074j)",
            vec!["quantity".into(), "value".into()],
        )
        .row(vec![
            "open-loop IPCJ poles [rad/s]".into(),
            pole(de.open_loop_poles[0]),
        ])
        .row(vec![
            "zeros [rad/s]".into(),
            format!("{:.4}, {:.4}, {:.4}", de.zeros[0], de.zeros[1], de.zeros[2]),
        ])
        .row(vec!["DC gain [m/rad]".into(), format!("{:.5}", de.dc_gain)])
        .row(vec![
            "K_f (continuous)".into(),
            format!("[{:.6}, {:.6}]", cd.gain[0], cd.gain[1]),
        ])
        .row(vec!["N".into(), format!("{:.6}", cd.feedforward)])
        .row(vec![
            "closed-loop IPCJ poles [rad/s]".into(),
            pole(cd.closed_loop_poles[0]),
        ])
        .row(vec![
            "K_d (200 Hz) on [θ, θ̇, z, p]".into(),
            format!(
                "[{:.6}, {:.6}, 0, 0]",
                de.discrete_gain[0], de.discrete_gain[1]
            ),
        ])
        .row(vec![
            "observer poles [rad/s]".into(),
            de.observer_poles.iter().map(|p| pole(*p)).collect::<Vec<_>>().join(", "),
        ]),
    );
    let mut t = Table::new(
        "Push tests: measured from the simulated ZMP (open loop → with controller)",
        vec![
            "phase".into(),
            "plane".into(),
            "peak [mm]".into(),
            "settling [s]".into(),
            "ζ measured".into(),
            "ζ designed".into(),
            "static gain model / open / closed [m/rad]".into(),
        ],
    );
    for (p, r) in &pushes {
        for m in &r.metrics {
            t = t.row(vec![
                p.name().to_uppercase(),
                format!("{:?}", m.plane),
                format!("{:.1} → {:.1}", 1e3 * m.open.peak, 1e3 * m.closed.peak),
                format!(
                    "{} → {}",
                    fmt_opt(m.open.settling_time),
                    fmt_opt(m.closed.settling_time)
                ),
                format!(
                    "{:.3} → {:.3}",
                    m.open.damping_ratio, m.closed.damping_ratio
                ),
                format!("{:.2}", m.designed_damping_ratio),
                format!(
                    "{:.4} / {:.4} / {:.4}",
                    m.static_gain_model, m.static_gain_open, m.static_gain_closed
                ),
            ]);
        }
    }
    s = s.table(t);
    for (href, text) in [
        (
            "balance/identify/summary.json",
            "identification summary (JSON)",
        ),
        ("balance/identify/bode.csv", "measured Bode data (CSV)"),
        ("balance/design/summary.json", "design summary (JSON)"),
        (
            "balance/push-dsp/summary.json",
            "push test DSP summary (JSON)",
        ),
        (
            "balance/push-dsp/zmp.csv",
            "push test DSP time series (CSV)",
        ),
        (
            "balance/push-ssp/summary.json",
            "push test SSP summary (JSON)",
        ),
        (
            "balance/push-ssp/zmp.csv",
            "push test SSP time series (CSV)",
        ),
    ] {
        s = s.link(href, text);
    }
    Ok(s)
}

fn fmt_opt(v: Option<f64>) -> String {
    v.map_or("—".into(), |x| format!("{x:.2}"))
}

fn write_json<T: Serialize>(path: &Path, value: &T) -> anyhow::Result<()> {
    let text = crate::finite::to_json(&path.display().to_string(), value)?;
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}

fn identify(out: &Path, seed: u64) -> anyhow::Result<IdentifyResult> {
    let mut sc = IdentifyScenario::default();
    sc.sim.seed = seed;
    let r = run_identify(&sc)?;
    let dir = out.join("identify");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let fig = Figure::new("Bode plot of y_ZMP/u, ỹz̃-DSP (Fig. 12)")
        .panel(
            Panel::new("Magnitude", "frequency [Hz]", "|y/u| [dB re 1 m/rad]")
                .with(Series::points(
                    "measured (sine sweep)",
                    r.measured.frequency_hz.clone(),
                    r.measured.magnitude_db.clone(),
                ))
                .with(Series::line(
                    "identified model (31)",
                    r.fitted.frequency_hz.clone(),
                    r.fitted.magnitude_db.clone(),
                ))
                .with(Series::dashed(
                    "true model",
                    r.truth.frequency_hz.clone(),
                    r.truth.magnitude_db.clone(),
                ))
                .log_x(),
        )
        .panel(
            Panel::new("Phase", "frequency [Hz]", "phase [deg]")
                .with(Series::points(
                    "measured (sine sweep)",
                    r.measured.frequency_hz.clone(),
                    r.measured.phase_deg.clone(),
                ))
                .with(Series::line(
                    "identified model (31)",
                    r.fitted.frequency_hz.clone(),
                    r.fitted.phase_deg.clone(),
                ))
                .with(Series::dashed(
                    "true model",
                    r.truth.frequency_hz.clone(),
                    r.truth.phase_deg.clone(),
                ))
                .log_x(),
        )
        .columns(1);
    write_figure(&fig, &dir, "bode")?;
    let rows: Vec<Vec<f64>> = (0..r.measured.frequency_hz.len())
        .map(|i| {
            vec![
                r.measured.frequency_hz[i],
                r.measured.magnitude_db[i],
                r.measured.phase_deg[i],
            ]
        })
        .collect();
    write_csv(
        &dir.join("bode.csv"),
        &[
            "frequency_hz".into(),
            "magnitude_db".into(),
            "phase_deg".into(),
        ],
        &rows,
    )?;
    #[derive(Serialize)]
    struct Summary<'a> {
        plant: &'a iktc::balance::PlantParams,
        identification: &'a iktc::balance::Identification,
        comparison: &'a [iktc::balance::ParameterComparison],
    }
    write_json(
        &dir.join("summary.json"),
        &Summary {
            plant: &r.plant,
            identification: &r.identification,
            comparison: &r.comparison,
        },
    )?;
    Ok(r)
}

/// Replaces points outside `|re|, |im| ≤ limit` by NaN so the line breaks there.
fn clip(points: &[[f64; 2]], limit: f64) -> (Vec<f64>, Vec<f64>) {
    points
        .iter()
        .map(|p| {
            if p[0].abs() <= limit && p[1].abs() <= limit {
                (p[0], p[1])
            } else {
                (f64::NAN, f64::NAN)
            }
        })
        .unzip()
}

/// All branches in one series (one colour), separated by NaN so the line breaks between them.
fn joined(branches: &[Vec<[f64; 2]>], limit: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for b in branches {
        let (bx, by) = clip(b, limit);
        x.extend(bx);
        y.extend(by);
        x.push(f64::NAN);
        y.push(f64::NAN);
    }
    (x, y)
}

fn locus_panel(r: &DesignResult, title: &str, limit: f64) -> Panel {
    let (lx, ly) = joined(&r.root_locus.branches, limit);
    let (dx, dy) = joined(&r.design_path.branches, limit);
    let (ox, oy) = clip(&r.open_loop_poles, limit);
    let (zx, zy) = clip(&r.zeros.map(|z| [z, 0.0]), limit);
    let (cx, cy) = clip(&r.continuous.closed_loop_poles, limit);
    Panel::new(title, "Re s [rad/s]", "Im s [rad/s]")
        .equal_aspect()
        .with(Series::line("root locus of 1 + kG(s), k ≥ 0", lx, ly))
        .with(Series::dashed("pole placement path κK_f, κ: 0 → 1", dx, dy))
        .with(Series::points("open-loop poles", ox, oy))
        .with(Series::points("zeros", zx, zy))
        .with(Series::points("designed poles (ζ = 0.72)", cx, cy))
}

fn design(out: &Path) -> anyhow::Result<DesignResult> {
    let r = run_design(&DesignScenario::default())?;
    let dir = out.join("design");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let fig = Figure::new("Root locus of the identified IPCJ system (Fig. 13)")
        .panel(locus_panel(&r, "Whole plane", 130.0))
        .panel(locus_panel(&r, "Near the IPCJ poles", 20.0))
        .columns(2)
        .panel_size(640, 560);
    write_figure(&fig, &dir, "root_locus")?;
    #[derive(Serialize)]
    struct Summary<'a> {
        params: &'a iktc::balance::FullModelParams,
        open_loop_modal: &'a iktc::balance::Modal,
        dc_gain: f64,
        open_loop_poles: [[f64; 2]; 4],
        zeros: [f64; 3],
        continuous: &'a iktc::balance::ContinuousDesign,
        discrete_gain: [f64; 4],
        discrete_feedforward: f64,
        observer_gain: [f64; 4],
        observer_poles: [[f64; 2]; 4],
    }
    write_json(
        &dir.join("summary.json"),
        &Summary {
            params: &r.params,
            open_loop_modal: &r.open_loop_modal,
            dc_gain: r.dc_gain,
            open_loop_poles: r.open_loop_poles,
            zeros: r.zeros,
            continuous: &r.continuous,
            discrete_gain: r.discrete_gain,
            discrete_feedforward: r.discrete_feedforward,
            observer_gain: r.observer_gain,
            observer_poles: r.observer_poles,
        },
    )?;
    Ok(r)
}

fn push(out: &Path, phase: Phase, seed: u64) -> anyhow::Result<PushResult> {
    let mut sc = PushScenario::new(phase.support())?;
    sc.sim.seed = seed;
    let r = run_push(&sc)?;
    let dir = out.join(format!("push-{}", phase.name()));
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let shown = r.time.iter().take_while(|t| **t <= 8.0).count();
    let t: Vec<f64> = r.time[..shown].to_vec();
    let mm = |v: &[f64]| v[..shown].iter().map(|x| 1e3 * x).collect::<Vec<_>>();
    let mut fig = Figure::new(format!(
        "ZMP after a push on the COM at {:.1} s, {} (Figs. 16–17)",
        sc.push_time,
        phase.name().to_uppercase()
    ));
    for (i, (axis, m)) in ["x̃", "ỹ"].iter().zip(&r.metrics).enumerate() {
        fig = fig.panel(
            Panel::new(
                format!(
                    "ZMP {axis}: ζ measured {:.2} → {:.2} (designed {:.2})",
                    m.open.damping_ratio, m.closed.damping_ratio, m.designed_damping_ratio
                ),
                "time [s]",
                format!("ZMP {axis} [mm]"),
            )
            .with(Series::line(
                "without controller",
                t.clone(),
                mm(&r.zmp_open[i]),
            ))
            .with(Series::line(
                "with controller",
                t.clone(),
                mm(&r.zmp_closed[i]),
            )),
        );
    }
    fig = fig.panel(
        Panel::new("Controller output", "time [s]", "COM offset Δc [mm]")
            .with(Series::line("Δc x̃", t.clone(), mm(&r.com_offset[0])))
            .with(Series::dashed("Δc ỹ", t.clone(), mm(&r.com_offset[1]))),
    );
    write_figure(&fig.columns(1), &dir, "zmp")?;
    let rows: Vec<Vec<f64>> = (0..r.time.len())
        .map(|k| {
            vec![
                r.time[k],
                r.zmp_open[0][k],
                r.zmp_open[1][k],
                r.zmp_closed[0][k],
                r.zmp_closed[1][k],
                r.com_offset[0][k],
                r.com_offset[1][k],
            ]
        })
        .collect();
    write_csv(
        &dir.join("zmp.csv"),
        &[
            "time_s",
            "zmp_x_open_m",
            "zmp_y_open_m",
            "zmp_x_closed_m",
            "zmp_y_closed_m",
            "com_offset_x_m",
            "com_offset_y_m",
        ]
        .map(String::from),
        &rows,
    )?;
    #[derive(Serialize)]
    struct Summary<'a> {
        scenario: &'a PushScenario,
        metrics: &'a [iktc::balance::PlanePushMetrics; 2],
        support: &'a [(f64, f64)],
        zmp_excursion_open: f64,
        zmp_excursion_closed: f64,
        health: &'a iktc::sim::HealthReport,
    }
    write_json(
        &dir.join("summary.json"),
        &Summary {
            scenario: &r.scenario,
            metrics: &r.metrics,
            support: &r.support,
            zmp_excursion_open: r.zmp_excursion_open,
            zmp_excursion_closed: r.zmp_excursion_closed,
            health: &r.health,
        },
    )?;
    Ok(r)
}
