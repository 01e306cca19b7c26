//! `reproduce`: the paper's §V experiment end to end — random baseline, EAE
//! with the determinant and with the eigenvalue OI, multi-start with Fedorov
//! polish, the relaxation bound, and the calibration simulation — written as
//! a Markdown report, a JSON summary and figures.

use super::figures;
use activecal::bound::{BoundSettings, RelaxationSolver, design_gap, relaxation_bound};
use activecal::criterion::{DCriterion, OiCriterion};
use activecal::identify::{LmSettings, MonteCarloSettings, compare_designs, paper_tables};
use activecal::model::Robot;
use activecal::pool::Pool;
use activecal::select::{
    Algorithm, Selection, Settings, design_rng, eae, multistart, random_search,
};
use anyhow::{Context, Result, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

/// The paper's reported figures (§V-C, §V-D).
const PAPER_RANDOM_OID: f64 = 2.5414e22;
const PAPER_RANDOM_OI: f64 = 0.096284;
const PAPER_EAE_OID: f64 = 1.4818e27;
const PAPER_EAE_OI: f64 = 0.11798;

/// Arguments of `reproduce`.
#[derive(Args)]
pub struct ReproduceArgs {
    /// Directory for report.md, report.json and the figures.
    #[arg(long, default_value = "reproduce")]
    pub out: PathBuf,
    /// Replace the files of an existing --out directory.
    #[arg(long)]
    pub force: bool,
    /// Lattice values per joint (the paper: 5).
    #[arg(long, default_value_t = 5)]
    pub levels: usize,
    /// Poses per design (the paper: 30).
    #[arg(long, default_value_t = 30)]
    pub n: usize,
    /// Initial EAE poses (the paper: 12).
    #[arg(long, default_value_t = 12)]
    pub initial: usize,
    /// Random designs of the baseline (the paper: 5,000).
    #[arg(long, default_value_t = 5000)]
    pub designs: usize,
    /// Starts of the multi-start EAE.
    #[arg(long, default_value_t = 20)]
    pub starts: usize,
    /// Monte-Carlo calibration trials per design.
    #[arg(long, default_value_t = 200)]
    pub trials: usize,
    /// Measurement noise σ per coordinate, metres (the paper: 1 cm).
    #[arg(long, default_value_t = 0.01)]
    pub noise: f64,
    /// Seed of every random choice.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Skip the eigenvalue-OI run (slow: an eigen-decomposition per candidate).
    #[arg(long)]
    pub skip_oi: bool,
}

fn l10(ln: f64) -> f64 {
    ln / std::f64::consts::LN_10
}

struct Steps {
    bar: ProgressBar,
}

impl Steps {
    fn new(n: u64) -> Self {
        let bar = ProgressBar::new(n);
        if std::io::stdout().is_terminal() {
            bar.set_style(
                ProgressStyle::with_template("{bar:30} {pos}/{len} {msg} ({elapsed})")
                    .expect("template"),
            );
        } else {
            bar.set_draw_target(ProgressDrawTarget::hidden());
        }
        Self { bar }
    }
    fn step(&self, msg: &'static str) {
        self.bar.set_message(msg);
        self.bar.inc(1);
    }
}

/// Runs `reproduce`.
pub fn cmd_reproduce(a: ReproduceArgs) -> Result<()> {
    if a.out.exists() {
        let non_empty = std::fs::read_dir(&a.out)
            .map(|mut d| d.next().is_some())
            .unwrap_or(true);
        if non_empty && !a.force {
            bail!(
                "{} exists and is not empty; pass --force to replace its files",
                a.out.display()
            );
        }
    }
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let clock = Instant::now();
    let steps = Steps::new(8);
    let robot = Robot::puma560();
    let pool = Pool::full(&robot, a.levels)?;
    let x = pool.jacobian(&robot, &robot.nominal);
    let p = x.p();
    let lat = |k: usize| pool.indices[k];
    let s = Settings {
        n: a.n,
        initial: a.initial,
        starts: a.starts,
        designs: a.designs,
        seed: a.seed,
        ..Settings::default()
    };
    s.validate(&x)?;

    // 1. Random baseline (§V-C).
    steps.step("random designs");
    let all: Vec<usize> = (0..x.n_poses()).collect();
    let rs = random_search(&x, &all, &[], a.n, a.designs, a.seed);
    let mut order: Vec<usize> = (0..rs.ln_oid.len()).collect();
    order.sort_by(|&i, &j| rs.ln_oid[i].total_cmp(&rs.ln_oid[j]));
    let median_k = order[order.len() / 2];
    let median_design =
        activecal::select::random_design(&mut design_rng(a.seed, median_k as u64), &all, &[], a.n);

    // 2. EAE with the paper's settings, determinant criterion (§V-D).
    steps.step("EAE (det)");
    let t0 = Instant::now();
    let e_det = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(a.seed, 0))?;
    let eae_seconds = t0.elapsed().as_secs_f64();
    // 3. The same start with the eigenvalue OI (Fig. 5).
    steps.step("EAE (eigenvalue OI)");
    let e_oi: Option<Selection> = if a.skip_oi {
        None
    } else {
        Some(eae(
            &x,
            &mut OiCriterion::new(),
            &s,
            &mut design_rng(a.seed, 0),
        )?)
    };
    // 4. Multi-start EAE + Fedorov polish; Fedorov and DETMAX alone.
    steps.step("multi-start EAE + Fedorov polish");
    let t0 = Instant::now();
    let best = multistart(
        &x,
        DCriterion::new,
        Algorithm::Eae,
        &Settings {
            polish: true,
            ..s.clone()
        },
    )?;
    let best_seconds = t0.elapsed().as_secs_f64();
    let fed = multistart(
        &x,
        DCriterion::new,
        Algorithm::Fedorov,
        &Settings {
            starts: 1,
            ..s.clone()
        },
    )?;
    let det = multistart(
        &x,
        DCriterion::new,
        Algorithm::Detmax,
        &Settings {
            starts: 1,
            ..s.clone()
        },
    )?;

    // 5. The relaxation bound.
    steps.step("relaxation bound");
    let bound = relaxation_bound(&x, a.n, &BoundSettings::default())?;
    // Cross-check: the same relaxation by the Newton barrier solver.
    let newton = relaxation_bound(
        &x,
        a.n,
        &BoundSettings::builder()
            .solver(RelaxationSolver::Newton)
            .build()?,
    )?;
    let named: Vec<(&str, Vec<usize>)> = vec![
        ("EAE (paper settings)", e_det.poses.clone()),
        ("multi-start EAE + polish", best.poses.clone()),
        ("Fedorov", fed.poses.clone()),
        ("DETMAX", det.poses.clone()),
        ("best random", rs.best.clone()),
        ("median random", median_design.clone()),
    ];
    let mut gaps = Vec::new();
    for (name, d) in &named {
        gaps.push((name.to_string(), design_gap(&x, d, &bound)?));
    }

    // 6. Calibration: Tables III/IV on the EAE design, Monte-Carlo on several.
    steps.step("calibration (Tables III, IV)");
    let qs: Vec<Vec<f64>> = e_det.poses.iter().map(|&k| pool.q(k)).collect();
    let tables = paper_tables(&robot, &qs, a.noise, a.seed, &LmSettings::default())?;
    steps.step("Monte-Carlo calibration");
    let mc_designs: Vec<(String, Vec<usize>)> = [0usize, 1, 2, 4, 5]
        .iter()
        .map(|&i| (named[i].0.to_string(), named[i].1.clone()))
        .collect();
    let mc = compare_designs(
        &robot,
        &pool,
        &mc_designs,
        &MonteCarloSettings {
            trials: a.trials,
            sigma: a.noise,
            seed: a.seed,
            ..MonteCarloSettings::default()
        },
    )?;

    // 7. Figures.
    steps.step("figures");
    let out = &a.out;
    figures::random_designs(&out.join("fig2_random_designs"), &rs.oi, e_det.oi)?;
    let tr_ln: Vec<f64> = e_det.trace.iter().map(|r| l10(r.ln_oid)).collect();
    figures::trace(
        &out.join("fig4_log10_oid"),
        "log10 OI_D per EAE iteration (Fig. 4)",
        "log10 OI_D",
        &[("EAE, det criterion", tr_ln.clone())],
    )?;
    let mut oi_series = vec![(
        "EAE, det criterion",
        e_det.trace.iter().map(|r| r.oi).collect::<Vec<_>>(),
    )];
    if let Some(o) = &e_oi {
        oi_series.push((
            "EAE, eigenvalue-OI criterion",
            o.trace.iter().map(|r| r.oi).collect(),
        ));
    }
    figures::trace(
        &out.join("fig5_oi"),
        "OI per EAE iteration (Fig. 5)",
        "OI, eq. (1)",
        &oi_series,
    )?;
    // 1/OI_D spans 20 decades: plotted as its log10 on a linear axis (a log
    // scale with every decade labelled).
    let inv: Vec<f64> = e_det.trace.iter().map(|r| -l10(r.ln_oid)).collect();
    figures::trace(
        &out.join("fig6_inverse_oid"),
        "1/OI_D per EAE iteration, log scale (Fig. 6)",
        "log10 (1/OI_D)",
        &[("EAE", inv)],
    )?;
    let digits = |d: &[usize]| -> Result<Vec<Vec<usize>>> {
        Ok(d.iter()
            .map(|&k| pool.lattice.digits(lat(k)))
            .collect::<activecal::Result<_>>()?)
    };
    figures::poses(
        &out.join("fig3_initial_poses"),
        "the initial EAE poses (Fig. 3)",
        &digits(&e_det.trace_initial())?,
        a.levels,
    )?;
    figures::poses(
        &out.join("fig4a_selected_poses"),
        "poses selected by EAE (Fig. 4 A)",
        &digits(&e_det.poses)?,
        a.levels,
    )?;

    // 8. Report.
    steps.step("report");
    let designs_json: Vec<Value> = named
        .iter()
        .zip(&gaps)
        .map(|((name, d), (_, g))| {
            json!({"name": name, "poses": d.iter().map(|&k| lat(k)).collect::<Vec<_>>(),
                   "log10_oid": g.log10_oid, "d_efficiency": g.d_efficiency})
        })
        .collect();
    let same_as_oi = e_oi.as_ref().map(|o| {
        let mut a1 = o.poses.clone();
        let mut b1 = e_det.poses.clone();
        a1.sort_unstable();
        b1.sort_unstable();
        a1 == b1
    });
    let summary = json!({
        "settings": {"levels": a.levels, "n": a.n, "initial": a.initial, "designs": a.designs, "starts": a.starts,
                     "trials": a.trials, "noise": a.noise, "seed": a.seed, "pool": pool.len(), "p": p},
        "random": {"best_log10_oid": l10(rs.best_ln_oid), "best_oi": activecal::select::oi_from_ln_oid(rs.best_ln_oid, p),
                   "median_log10_oid": l10(rs.ln_oid[median_k]), "best_poses": rs.best.iter().map(|&k| lat(k)).collect::<Vec<_>>()},
        "eae": {"log10_oid": l10(e_det.ln_oid), "oi": e_det.oi, "seconds": eae_seconds,
                "poses": e_det.poses.iter().map(|&k| lat(k)).collect::<Vec<_>>(),
                "trace_log10_oid": tr_ln},
        "eae_oi": e_oi.as_ref().map(|o| json!({"log10_oid": l10(o.ln_oid), "oi": o.oi, "same_design": same_as_oi,
                "poses": o.poses.iter().map(|&k| lat(k)).collect::<Vec<_>>()})),
        "multistart": {"log10_oid": l10(best.ln_oid), "oi": best.oi, "seconds": best_seconds, "best_start": best.start},
        "fedorov": {"log10_oid": l10(fed.ln_oid)},
        "detmax": {"log10_oid": l10(det.ln_oid)},
        "bound": {"log10_bound": bound.log10_bound(), "ln_bound": bound.ln_bound, "ln_primal": bound.ln_primal,
                  "certificate_gap": bound.certificate_gap, "support_size": bound.support_size, "seconds": bound.seconds,
                  "status": format!("{:?}", bound.status),
                  "newton": {"log10_bound": newton.log10_bound(), "ln_bound": newton.ln_bound, "ln_primal": newton.ln_primal,
                             "certificate_gap": newton.certificate_gap, "seconds": newton.seconds,
                             "status": format!("{:?}", newton.status)}},
        "designs": designs_json,
        "tables": {"estimate": tables.estimate, "residual": tables.residual, "std": tables.std,
                   "iterations": tables.identification.iterations, "status": format!("{:?}", tables.identification.status)},
        "monte_carlo": mc.designs.iter().map(|d| json!({
            "design": d.design, "trials": d.trials, "converged": d.converged,
            "rmse_median_over_predicted": d.rmse_over_predicted.as_ref().map(|s| s.median),
            "param_rmse": d.parameters.iter().map(|q| (q.name.clone(), q.rmse)).collect::<std::collections::BTreeMap<_, _>>(),
            "ln_generalized_variance_ratio": d.generalized_variance.as_ref().map(|g| g.ln_ratio),
            "validation_rms_before": d.validation_rms_before,
            "validation_rms_after_median": d.validation_rms_after.as_ref().map(|s| s.median),
        })).collect::<Vec<_>>(),
        "seconds": clock.elapsed().as_secs_f64(),
    });
    std::fs::write(
        out.join("report.json"),
        serde_json::to_string_pretty(&summary)? + "\n",
    )?;
    std::fs::write(
        out.join("report.md"),
        markdown(&a, &summary, &mc.designs, &tables),
    )?;
    steps.bar.finish_and_clear();
    println!(
        "wrote {}/report.md, report.json and figures in {:.1} s",
        out.display(),
        clock.elapsed().as_secs_f64()
    );
    Ok(())
}

fn fmt_opt(v: &Value, digits: usize) -> String {
    v.as_f64().map_or("–".into(), |x| format!("{x:.digits$}"))
}

fn markdown(
    a: &ReproduceArgs,
    s: &Value,
    mc: &[activecal::identify::MonteCarloSummary],
    t: &activecal::identify::PaperTables,
) -> String {
    let mut m = String::new();
    let _ = writeln!(
        m,
        "# Reproduction of Sun & Hollerbach §V (PUMA 560, 27 unknowns)\n"
    );
    let _ = writeln!(
        m,
        "Pool: {}-level lattice, {} poses; designs of N = {}; EAE from {} random poses; seed {}; {} random designs; {} multi-start runs; σ = {} m.\n",
        a.levels, s["settings"]["pool"], a.n, a.initial, a.seed, a.designs, a.starts, a.noise
    );
    let _ = writeln!(m, "## Summary: paper against ours\n");
    let _ = writeln!(m, "| quantity | paper | ours |");
    let _ = writeln!(m, "|---|---|---|");
    let rnd = s["random"]["best_log10_oid"].as_f64().unwrap_or(f64::NAN);
    let e = s["eae"]["log10_oid"].as_f64().unwrap_or(f64::NAN);
    let best = s["multistart"]["log10_oid"].as_f64().unwrap_or(f64::NAN);
    let _ = writeln!(
        m,
        "| best random design, log10 OI_D | {:.4} | {:.4} |",
        PAPER_RANDOM_OID.log10(),
        rnd
    );
    let _ = writeln!(
        m,
        "| best random design, OI | {PAPER_RANDOM_OI} | {} |",
        fmt_opt(&s["random"]["best_oi"], 6)
    );
    let _ = writeln!(
        m,
        "| EAE design, log10 OI_D | {:.4} | {:.4} |",
        PAPER_EAE_OID.log10(),
        e
    );
    let _ = writeln!(
        m,
        "| EAE design, OI | {PAPER_EAE_OI} | {} |",
        fmt_opt(&s["eae"]["oi"], 6)
    );
    let _ = writeln!(
        m,
        "| EAE / best random, OI_D ratio | {:.4e} | {:.4e} |",
        PAPER_EAE_OID / PAPER_RANDOM_OID,
        10f64.powf(e - rnd)
    );
    let _ = writeln!(
        m,
        "| multi-start EAE + Fedorov polish, log10 OI_D | – | {best:.4} |"
    );
    let _ = writeln!(
        m,
        "| relaxation upper bound, log10 OI_D | – | {} |",
        fmt_opt(&s["bound"]["log10_bound"], 4)
    );
    if let Some(same) = s["eae_oi"]["same_design"].as_bool() {
        let _ = writeln!(
            m,
            "| OI criterion selects the same poses as det | yes | {} |",
            if same { "yes" } else { "no" }
        );
    }
    let _ = writeln!(
        m,
        "\nThe paper's best random design (OI_D {PAPER_RANDOM_OID:.4e}) lies at the bottom of our distribution of random lattice designs \
(median log10 OI_D {}), while our EAE matches the paper's EAE: the model and the criterion agree, the random baseline does not. \
The paper does not say how its random designs were drawn; ours are uniform 30-subsets of the lattice. The EAE-to-random ratio \
is therefore about {:.0}x here, not 50,000x.",
        fmt_opt(&s["random"]["median_log10_oid"], 3),
        10f64.powf(e - rnd)
    );
    let _ = writeln!(m, "\n## Designs and their D-efficiency against the bound\n");
    let _ = writeln!(m, "| design | log10 OI_D | D-efficiency |");
    let _ = writeln!(m, "|---|---|---|");
    for d in s["designs"].as_array().into_iter().flatten() {
        let _ = writeln!(
            m,
            "| {} | {} | {} |",
            d["name"].as_str().unwrap_or(""),
            fmt_opt(&d["log10_oid"], 4),
            fmt_opt(&d["d_efficiency"], 4)
        );
    }
    let _ = writeln!(
        m,
        "\nBound: status {}, certificate gap {:.2e} (ln det), {} poses carry weight, {:.2} s.\n",
        s["bound"]["status"].as_str().unwrap_or(""),
        s["bound"]["certificate_gap"].as_f64().unwrap_or(f64::NAN),
        s["bound"]["support_size"],
        s["bound"]["seconds"].as_f64().unwrap_or(f64::NAN)
    );
    let nb = &s["bound"]["newton"];
    let _ = writeln!(
        m,
        "Cross-check by the Newton barrier solver (`bound --solver newton`): ln bound {:.9} against Clarabel's {:.9}, ln primal {:.9} against {:.9}, status {}, certificate gap {:.2e}, {:.2} s.\n",
        nb["ln_bound"].as_f64().unwrap_or(f64::NAN),
        s["bound"]["ln_bound"].as_f64().unwrap_or(f64::NAN),
        nb["ln_primal"].as_f64().unwrap_or(f64::NAN),
        s["bound"]["ln_primal"].as_f64().unwrap_or(f64::NAN),
        nb["status"].as_str().unwrap_or(""),
        nb["certificate_gap"].as_f64().unwrap_or(f64::NAN),
        nb["seconds"].as_f64().unwrap_or(f64::NAN)
    );
    for (title, grid) in [
        ("Table III: estimated parameters (EAE design)", &t.estimate),
        ("Table IV: residuals, real − estimate", &t.residual),
    ] {
        let _ = writeln!(m, "## {title}\n");
        let _ = writeln!(m, "| frame | gamma | alpha | a | d | beta |");
        let _ = writeln!(m, "|---|---|---|---|---|---|");
        for (f, row) in grid.frames.iter().zip(&grid.rows) {
            let cells: Vec<String> = row
                .iter()
                .map(|c| c.map_or("–".into(), |v| format!("{v:.6}")))
                .collect();
            let _ = writeln!(m, "| {f} | {} |", cells.join(" | "));
        }
        let _ = writeln!(m);
    }
    let _ = writeln!(
        m,
        "## Monte-Carlo calibration ({} trials per design, σ = {} m)\n",
        a.trials, a.noise
    );
    let _ = writeln!(
        m,
        "| design | converged | √Σ RMSE² angles (rad) | √Σ RMSE² lengths (m) | median RMSE / predicted σ | ln det(C_emp)/det(C_pred) | validation RMS before (m) | validation RMS after, median (m) |"
    );
    let _ = writeln!(m, "|---|---|---|---|---|---|---|---|");
    for d in mc {
        // Angles are the γ, α, β unknowns; lengths the a, d ones.
        let (mut ang, mut len) = (0.0f64, 0.0f64);
        for q in &d.parameters {
            let angle = ["gamma_", "alpha_", "beta_"]
                .iter()
                .any(|p| q.name.starts_with(p));
            *(if angle { &mut ang } else { &mut len }) += q.rmse * q.rmse;
        }
        let _ = writeln!(
            m,
            "| {} | {}/{} | {:.5} | {:.5} | {} | {} | {:.6} | {} |",
            d.design,
            d.converged,
            d.trials,
            ang.sqrt(),
            len.sqrt(),
            d.rmse_over_predicted
                .as_ref()
                .map_or("–".into(), |s| format!("{:.3}", s.median)),
            d.generalized_variance
                .as_ref()
                .map_or("–".into(), |g| format!("{:.3}", g.ln_ratio)),
            d.validation_rms_before,
            d.validation_rms_after
                .as_ref()
                .map_or("–".into(), |s| format!("{:.6}", s.median)),
        );
    }
    let _ = writeln!(m, "\n## Figures\n");
    for (f, what) in [
        (
            "fig2_random_designs",
            "OI of every random design and their histogram (Fig. 2); the red line is the EAE design",
        ),
        (
            "fig3_initial_poses",
            "the initial EAE poses as lattice digits per joint (Fig. 3)",
        ),
        ("fig4_log10_oid", "log10 OI_D per EAE iteration (Fig. 4 B)"),
        ("fig4a_selected_poses", "the selected poses (Fig. 4 A)"),
        (
            "fig5_oi",
            "OI per iteration, determinant and eigenvalue criteria (Fig. 5 B)",
        ),
        (
            "fig6_inverse_oid",
            "1/OI_D per iteration, log scale (Fig. 6)",
        ),
    ] {
        let _ = writeln!(m, "- [{f}.png]({f}.png) ([svg]({f}.svg)): {what}");
    }
    m
}
