//! The balance scenarios run and their output files written: identify (Fig. 12), design
//! (Fig. 13), push (Figs. 16–17).

use std::path::Path;

use anyhow::Context;
use iktc::balance::{
    run_design, run_identify, run_push, DesignResult, DesignScenario, IdentifyResult,
    IdentifyScenario, PushResult, PushScenario,
};
use iktc_report::{write_csv, write_figure, Figure, Panel, Series};
use serde::Serialize;

use super::Phase;

/// Writes `value` as JSON to `path`.
fn write_json<T: Serialize>(path: &Path, value: &T) -> anyhow::Result<()> {
    let text = crate::finite::to_json(&path.display().to_string(), value)?;
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}

/// Runs the identification (sensor noise seeded by `seed`) and writes its Bode plot, bode.csv
/// and summary.json to `out/identify`.
pub fn identify(out: &Path, seed: u64) -> anyhow::Result<IdentifyResult> {
    let mut sc = IdentifyScenario::default();
    sc.sim.seed = seed;
    let r = run_identify(&sc)?;
    let dir = out.join("identify");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    write_figure(&bode_figure(&r), &dir, "bode")?;
    write_bode_csv(&r, &dir)?;
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

/// Fig. 12: the Bode plot (magnitude [dB re 1 m/rad], phase [deg]) measured, fitted and true.
fn bode_figure(r: &IdentifyResult) -> Figure {
    Figure::new("Bode plot of y_ZMP/u, ỹz̃-DSP (Fig. 12)")
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
        .columns(1)
}

/// Writes bode.csv: the measured frequency [Hz], magnitude [dB] and phase [deg].
fn write_bode_csv(r: &IdentifyResult, dir: &Path) -> anyhow::Result<()> {
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
    Ok(())
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

/// The root locus, the pole placement path and the poles and zeros [rad/s] within `limit`.
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

/// Runs the pole placement and writes its root locus and summary.json to `out/design`.
pub fn design(out: &Path) -> anyhow::Result<DesignResult> {
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

/// Runs the push test in `phase` (sensor noise seeded by `seed`) and writes its ZMP figure,
/// zmp.csv and summary.json to `out/push-<phase>`.
pub fn push(out: &Path, phase: Phase, seed: u64) -> anyhow::Result<PushResult> {
    let mut sc = PushScenario::new(phase.support())?;
    sc.sim.seed = seed;
    let r = run_push(&sc)?;
    let dir = out.join(format!("push-{}", phase.name()));
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    write_figure(&zmp_figure(&sc, phase, &r).columns(1), &dir, "zmp")?;
    write_zmp_csv(&r, &dir)?;
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

/// Figs. 16–17: the ZMP [mm] over the first 8 s with and without the controller, and the
/// controller's COM offset [mm].
fn zmp_figure(sc: &PushScenario, phase: Phase, r: &PushResult) -> Figure {
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
    fig.panel(
        Panel::new("Controller output", "time [s]", "COM offset Δc [mm]")
            .with(Series::line("Δc x̃", t.clone(), mm(&r.com_offset[0])))
            .with(Series::dashed("Δc ỹ", t.clone(), mm(&r.com_offset[1]))),
    )
}

/// Writes zmp.csv: time [s], the ZMP open and closed loop and the COM offset [m].
fn write_zmp_csv(r: &PushResult, dir: &Path) -> anyhow::Result<()> {
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
    Ok(())
}
