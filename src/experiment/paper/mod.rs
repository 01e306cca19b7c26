//! The paper's §V experiment end to end, on the PUMA 560: random baseline
//! (§V-C), EAE with the determinant and with the eigenvalue OI (§V-D,
//! Fig. 5), multi-start EAE with a Fedorov polish, Fedorov and DETMAX alone,
//! the certified relaxation bound (cross-checked by the Newton solver), each
//! design's D-efficiency, Tables III/IV and a Monte-Carlo comparison of the
//! designs. [`run`] returns a typed [`PaperReport`]; [`PaperReport::markdown`]
//! renders it. Figures are left to the caller ([`FigureData`]).

mod assemble;
pub mod figures;
pub mod folder;
mod markdown;
mod report;
mod settings;

pub use report::{
    BoundSummary, DesignRow, EaeOiSummary, EaeSummary, FigureData, Log10Oid, MonteCarloRow,
    MultistartSummary, NewtonCheck, PaperReport, RandomSummary, SettingsSummary, TablesSummary,
};
pub use settings::PaperSettings;

use crate::bound::{BoundSettings, DesignGap, RelaxationSolver, design_gap, relaxation_bound};
use crate::criterion::{DCriterion, OiCriterion};
use crate::identify::{LmSettings, MonteCarloSettings, PaperTables, compare_designs, paper_tables};
use crate::model::Robot;
use crate::pool::PoolSpec;
use crate::select::{
    Algorithm, Selection, Settings, design_rng, eae, multistart, random_design, random_search,
};
use assemble::Parts;
use std::time::Instant;

/// The paper's best random design, OI_D (§V-C).
pub const PAPER_RANDOM_OID: f64 = 2.5414e22;
/// The paper's best random design, OI (§V-C).
pub const PAPER_RANDOM_OI: f64 = 0.096284;
/// The paper's EAE design, OI_D (§V-D).
pub const PAPER_EAE_OID: f64 = 1.4818e27;
/// The paper's EAE design, OI (§V-D).
pub const PAPER_EAE_OI: f64 = 0.11798;

pub use super::error::ExperimentError;

/// Steps [`run`] reports to its progress callback.
pub const STEPS: u64 = 7;

/// The random baseline (§V-C): the best of `designs` random designs and
/// the median one (its design drawn again from its seed).
struct RandomBaseline {
    search: crate::select::RandomSearch,
    median_j: usize,
    median_design: Vec<usize>,
}

fn random_baseline(x: &crate::blocks::Blocks, a: &PaperSettings) -> RandomBaseline {
    let all: Vec<usize> = (0..x.n_poses()).collect();
    let rs = random_search(&x, None, &all, &[], a.n, a.designs, a.seed);
    // The median of the kept designs (all of them up to SAMPLE_CAP).
    let mut order: Vec<usize> = (0..rs.ln_oid.len()).collect();
    order.sort_by(|&i, &j| rs.ln_oid[i].total_cmp(&rs.ln_oid[j]));
    let median_j = order[order.len() / 2];
    let median_k = median_j * rs.stride;
    let median_design = random_design(&mut design_rng(a.seed, median_k as u64), &all, &[], a.n);

    RandomBaseline {
        search: rs,
        median_j,
        median_design,
    }
}

/// The selections of §V-D: EAE with the paper's settings (determinant, and
/// the eigenvalue OI unless skipped), multi-start EAE with a Fedorov polish,
/// Fedorov and DETMAX alone.
struct Selections {
    e_det: Selection,
    eae_seconds: f64,
    e_oi: Option<Selection>,
    best: Selection,
    best_seconds: f64,
    fed: Selection,
    det: Selection,
}

fn selections(
    x: &crate::blocks::Blocks,
    a: &PaperSettings,
    s: &Settings,
    progress: &mut impl FnMut(&'static str),
) -> Result<Selections, ExperimentError> {
    progress("EAE (det)");
    let t0 = Instant::now();
    let e_det = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(a.seed, 0))?;
    let eae_seconds = t0.elapsed().as_secs_f64();
    // 3. The same start with the eigenvalue OI (Fig. 5).
    progress("EAE (eigenvalue OI)");
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
    progress("multi-start EAE + Fedorov polish");
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
    let one_start = Settings {
        starts: 1,
        ..s.clone()
    };
    let fed = multistart(&x, DCriterion::new, Algorithm::Fedorov, &one_start)?;
    let det = multistart(&x, DCriterion::new, Algorithm::Detmax, &one_start)?;

    Ok(Selections {
        e_det,
        eae_seconds,
        e_oi,
        best,
        best_seconds,
        fed,
        det,
    })
}

/// Runs the experiment; `progress` is called with the name of each of the
/// [`STEPS`] stages as it starts.
pub fn run(
    a: &PaperSettings,
    mut progress: impl FnMut(&'static str),
) -> Result<PaperReport, ExperimentError> {
    a.validate()?;
    let clock = Instant::now();
    let robot = Robot::puma560();
    let pool = PoolSpec::lattice(a.levels).build(&robot, &robot.nominal)?;
    let x = pool.try_jacobian(&robot, &robot.nominal)?;
    let s = Settings::builder()
        .n(a.n)
        .initial(a.initial)
        .starts(a.starts)
        .designs(a.designs)
        .seed(a.seed)
        .build()?;
    s.validate_for(&x)?;
    // 1. Random baseline (§V-C).
    progress("random designs");
    let random = random_baseline(&x, a);
    // 2.–4. EAE, its eigenvalue-OI twin, multi-start, Fedorov, DETMAX.
    let sel = selections(&x, a, &s, &mut progress)?;
    // 5. The relaxation bound, cross-checked by the Newton barrier solver.
    progress("relaxation bound");
    let bound = relaxation_bound(&x, None, a.n, &BoundSettings::default())?;
    let newton = relaxation_bound(
        &x,
        None,
        a.n,
        &BoundSettings::builder()
            .solver(RelaxationSolver::Newton)
            .build()?,
    )?;
    let named: Vec<(&str, Vec<usize>)> = vec![
        ("EAE (paper settings)", sel.e_det.poses.clone()),
        ("multi-start EAE + polish", sel.best.poses.clone()),
        ("Fedorov", sel.fed.poses.clone()),
        ("DETMAX", sel.det.poses.clone()),
        ("best random", random.search.best.clone()),
        ("median random", random.median_design.clone()),
    ];
    let gaps: Vec<DesignGap> = named
        .iter()
        .map(|(_, d)| design_gap(&x, None, d, &bound))
        .collect::<Result<_, _>>()?;
    // 6. Calibration: Tables III/IV on the EAE design, Monte-Carlo on several.
    progress("calibration (Tables III, IV)");
    let e_det = &sel.e_det;
    let qs: Vec<Vec<f64>> = e_det.poses.iter().map(|&k| pool.q(k)).collect();
    let tables: PaperTables = paper_tables(&robot, &qs, a.noise, a.seed, &LmSettings::default())?;
    progress("Monte-Carlo calibration");
    let mc_designs: Vec<(String, Vec<usize>)> = [0usize, 1, 2, 4, 5]
        .iter()
        .map(|&i| (named[i].0.to_string(), named[i].1.clone()))
        .collect();
    let mc = compare_designs(
        &robot,
        &pool,
        &mc_designs,
        &MonteCarloSettings::builder()
            .trials(a.trials)
            .sigma(a.noise)
            .seed(a.seed)
            .build()?,
    )?;

    let lattice = pool.lattice().expect("a lattice pool");
    let digits = |d: &[usize]| -> Result<Vec<Vec<usize>>, crate::Error> {
        d.iter().map(|&k| lattice.digits(pool.id(k))).collect()
    };
    let figures = FigureData {
        random_oi: random.search.oi.clone(),
        eae_oi: e_det.oi,
        eae_trace_oi: e_det.trace.iter().map(|r| r.oi).collect(),
        eae_oi_trace_oi: sel
            .e_oi
            .as_ref()
            .map(|o| o.trace.iter().map(|r| r.oi).collect()),
        initial_digits: digits(&e_det.trace_initial())?,
        selected_digits: digits(&e_det.poses)?,
    };
    let parts = Parts {
        pool: &pool,
        robot: &robot,
        p: x.p(),
        random: &random,
        sel: &sel,
        bound: &bound,
        newton: &newton,
        named: &named,
        gaps: &gaps,
        tables: &tables,
    };
    Ok(parts.report(a, mc, figures, clock.elapsed().as_secs_f64()))
}
