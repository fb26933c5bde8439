//! The damping-controller section of the report (`iktc reproduce`).

use std::path::Path;

use iktc::balance::{DesignResult, IdentifyResult, PushResult};
use iktc_report::{Section, Table};

use super::{design, fmt_opt, identify, push, Phase};

/// The section's introduction (HTML).
const INTRO: &str =
    "<p>The ZMP damping controller on the inverted pendulum with a compliant joint (IPCJ), \
         with the errata's corrected model (27), (31)–(33). A synthetic robot (l = 0.8 m, \
         45 kg, τ<sub>s</sub> = 20 ms, true delay 20 ms, 0.5 mm ZMP noise) stands in for Hubo. \
         <b>Identify</b>: a sine sweep at 200 Hz, fitted by Levenberg–Marquardt (Fig. 12). \
         <b>Design</b>: pole placement to ζ = 0.72, keeping the lag and Padé poles (Fig. 13). \
         <b>Push</b>: a 2 N·s impulse on the COM, with and without the controller \
         (Figs. 16–17); the damping ratio is fitted to the ZMP response.</p>";

/// The section's links to the data files (path relative to the output directory, text).
const LINKS: [(&str, &str); 7] = [
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
];

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
    let mut s = figures(
        Section::new("Damping controller (Section 4)").intro(INTRO),
        &pushes,
    );
    s = s.table(identification_table(&id));
    s = s.table(design_table(&de));
    s = s.table(push_table(&pushes));
    for (href, text) in LINKS {
        s = s.link(href, text);
    }
    Ok(s)
}

/// `s` with Figs. 12, 13 and the ZMP figure of each push.
fn figures(mut s: Section, pushes: &[(Phase, PushResult)]) -> Section {
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
    for (p, _) in pushes {
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
    s
}

/// The true against the identified plant parameters (errors in %).
fn identification_table(id: &IdentifyResult) -> Table {
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
    t
}

/// The design's poles and zeros [rad/s], DC gain [m/rad] and gains.
fn design_table(de: &DesignResult) -> Table {
    let cd = &de.continuous;
    let pole = |p: [f64; 2]| format!("{:.4} {:+.4}j", p[0], p[1]);
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
    ])
}

/// The push tests, open loop → with controller (peaks in mm, settling in s, static gains in
/// m/rad).
fn push_table(pushes: &[(Phase, PushResult)]) -> Table {
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
    for (p, r) in pushes {
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
    t
}
