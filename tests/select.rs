//! Pose selection on the PUMA: quality against the paper, determinism across
//! thread counts, fixed poses, rank-deficient starts, and local optimality.

use activecal::blocks::Blocks;
use activecal::criterion::design_ln_det;
use activecal::criterion::{DCriterion, OiCriterion};
use activecal::model::Robot;
use activecal::pool::Pool;
use activecal::select::{
    Algorithm, Settings, StepKind, design_rng, detmax, eae, fedorov, multistart,
};
use std::f64::consts::LN_10;

fn puma_pool(levels: usize) -> Blocks {
    let r = Robot::puma560();
    Pool::full(&r, levels).unwrap().jacobian(&r, &r.nominal)
}

/// Runs `f` inside a rayon pool of `threads` threads.
fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// Brute force: no swap of a design pose (other than `fixed`) for a pool
/// pose outside the design improves ln det, each swap recomputed from
/// scratch. The searches' improvement tolerance is 1e-10 relative (ln det
/// ≈ 20 on these pools) and the recomputation adds ~1e-12: 1e-7 is ample
/// and far below any real improvement.
fn assert_no_improving_swap(x: &Blocks, poses: &[usize], fixed: &[usize]) {
    let base = design_ln_det(x, None, poses).unwrap();
    for k in 0..poses.len() {
        if fixed.contains(&poses[k]) {
            continue;
        }
        for i in 0..x.n_poses() {
            if poses.contains(&i) {
                continue;
            }
            let mut d = poses.to_vec();
            d[k] = i;
            if let Some(v) = design_ln_det(x, None, &d) {
                assert!(v <= base + 1e-7, "swap {k}->{i} improves {base} to {v}");
            }
        }
    }
}

#[test]
fn one_eae_start_reaches_paper_level() {
    let x = puma_pool(5);
    let s = Settings::default();
    let sel = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(1, 0)).unwrap();
    assert_eq!(sel.poses.len(), 30);
    // The paper's EAE design: OI_D = 1.4818e27 (log10 27.17); the bar is 27.0.
    assert!(
        sel.ln_oid / LN_10 >= 27.0,
        "log10 OI_D {}",
        sel.ln_oid / LN_10
    );
    // The reported value is ln det of the design, recomputed from scratch.
    // Tolerance: updates drift by ~p·u·κ(M) per step with κ ≈ 1e8 here,
    // refactorized every 64 updates: 1e-6 absolute in ln det is ample.
    let direct = design_ln_det(&x, None, &sel.poses).unwrap();
    assert!(
        (direct - sel.ln_oid).abs() < 1e-6,
        "{direct} vs {}",
        sel.ln_oid
    );
    // The trace: init, exchanges, 18 adds, exchanges; ln det never decreases.
    assert_eq!(sel.trace[0].kind, StepKind::Init);
    assert_eq!(
        sel.trace.iter().filter(|r| r.kind == StepKind::Add).count(),
        18
    );
    for w in sel.trace.windows(2) {
        assert!(w[1].ln_oid >= w[0].ln_oid - 1e-9);
    }
    assert_eq!(sel.trace.last().unwrap().ln_oid, sel.ln_oid);
}

#[test]
fn same_seed_same_design_whatever_the_thread_count() {
    let x = puma_pool(4);
    let s = Settings::builder()
        .starts(3)
        .polish(true)
        .seed(7)
        .build()
        .unwrap();
    let run = |threads: usize| {
        on_threads(threads, || {
            multistart(&x, DCriterion::new, Algorithm::Eae, &s).unwrap()
        })
    };
    let a = run(1);
    let b = run(3);
    assert_eq!(a.poses, b.poses);
    assert_eq!(a.trace, b.trace);
    assert_eq!(a.start_ln_oid, b.start_ln_oid);
    let ra = on_threads(1, || {
        multistart(
            &x,
            DCriterion::new,
            Algorithm::Random,
            &s.clone().into_builder().designs(200).build().unwrap(),
        )
        .unwrap()
    });
    let rb = multistart(
        &x,
        DCriterion::new,
        Algorithm::Random,
        &s.clone().into_builder().designs(200).build().unwrap(),
    )
    .unwrap();
    assert_eq!(ra.poses, rb.poses);
    // A different seed gives a different start.
    let c = multistart(
        &x,
        DCriterion::new,
        Algorithm::Eae,
        &s.clone().into_builder().seed(8).build().unwrap(),
    )
    .unwrap();
    assert_ne!(a.trace[0], c.trace[0]);
}

#[test]
fn fedorov_result_has_no_improving_exchange() {
    // Brute-force check on a 729-pose pool: no (out, in) swap improves ln det
    // by more than the search's own tolerance.
    let x = puma_pool(3);
    let s = Settings::builder().n(12).build().unwrap();
    let sel = fedorov(&x, &mut DCriterion::new(), &s, &mut design_rng(3, 0)).unwrap();
    assert_no_improving_swap(&x, &sel.poses, &[]);
}

#[test]
fn detmax_stops_when_the_added_pose_is_removed() {
    let x = puma_pool(4);
    let s = Settings::default();
    let sel = detmax(&x, &mut DCriterion::new(), &s, &mut design_rng(5, 0)).unwrap();
    assert_eq!(sel.poses.len(), 30);
    let n = sel.trace.len();
    let (add, rem) = (&sel.trace[n - 2], &sel.trace[n - 1]);
    assert_eq!(add.kind, StepKind::Add);
    assert_eq!(rem.kind, StepKind::Remove);
    assert_eq!(add.added, rem.removed);
    assert!(sel.ln_oid > sel.trace[0].ln_oid);
}

#[test]
fn fixed_poses_stay_and_rank_deficient_start_works() {
    let x = puma_pool(4);
    let fixed = vec![0, 100, 4095];
    // n0 = 3 poses: 9 rows < 27 unknowns, so the start needs the ridge.
    let s = Settings::builder()
        .initial(3)
        .fixed(fixed.clone())
        .build()
        .unwrap();
    let sel = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(2, 0)).unwrap();
    for f in &fixed {
        assert!(sel.poses.contains(f));
    }
    assert!(sel.trace[0].ridge);
    assert!(sel.trace.iter().any(|r| r.kind == StepKind::DropRidge));
    assert!(!sel.trace.last().unwrap().ridge);
    assert!(
        sel.trace
            .iter()
            .all(|r| r.removed.is_none_or(|p| !fixed.contains(&p)))
    );
    let direct = design_ln_det(&x, None, &sel.poses).unwrap();
    assert!((direct - sel.ln_oid).abs() < 1e-6);
    // Same quality class as a full-rank start (within 1 decade of OI_D).
    let plain = eae(
        &x,
        &mut DCriterion::new(),
        &Settings::default(),
        &mut design_rng(2, 0),
    )
    .unwrap();
    assert!(
        sel.ln_oid > plain.ln_oid - LN_10,
        "{} vs {}",
        sel.ln_oid,
        plain.ln_oid
    );
}

#[test]
fn oi_and_det_criteria_choose_the_same_design() {
    // The paper (§V-D): the eigenvalue OI and the determinant select the same
    // poses from the same start. OI is a monotone function of ln det for
    // full-rank designs, so the searches agree unless two candidates tie to
    // rounding.
    let x = puma_pool(3);
    let s = Settings::builder().n(15).initial(10).build().unwrap();
    let d = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(4, 0)).unwrap();
    let o = eae(&x, &mut OiCriterion::new(), &s, &mut design_rng(4, 0)).unwrap();
    assert_eq!(d.poses, o.poses);
    assert!((d.ln_oid - o.ln_oid).abs() < 1e-9 * d.ln_oid.abs());
}

#[test]
fn bad_settings_are_errors() {
    let x = puma_pool(3);
    // The checks that need no pool fail in `build`, the others in `eae`.
    let bad = |b: activecal::select::SettingsBuilder| match b.build() {
        Err(e) => e.to_string(),
        Ok(s) => eae(&x, &mut DCriterion::new(), &s, &mut design_rng(0, 0))
            .unwrap_err()
            .to_string(),
    };
    assert!(bad(Settings::builder().n(1000)).contains("larger than the pool"));
    assert!(bad(Settings::builder().n(8).initial(8)).contains("fewer than the 27 unknowns"));
    assert!(bad(Settings::builder().fixed(vec![729])).contains("not in the pool"));
    assert!(bad(Settings::builder().fixed(vec![3, 3])).contains("more than once"));
    assert!(
        bad(Settings::builder()
            .n(10)
            .initial(10)
            .fixed((0..11).collect()))
        .contains("do not fit")
    );
    assert!(bad(Settings::builder().ils(3).kick(0)).contains("kick must be at least 1"));
}

#[test]
fn score_indices_agree_with_an_independent_cholesky_to_1e_10() {
    // `score` computes ln OI_D from the singular values of the stacked X;
    // here it is checked against ln det(XᵀX) by Cholesky. Both are backward
    // stable: the relative error of ln det is ~p·ε·κ(X)²/|ln det| ≈
    // 27·2e-16·1e8/60 ≈ 1e-8 at worst for κ(X) = 1e4, far less in practice;
    // 1e-10 relative is what the issue asks and what these designs meet.
    use activecal::criterion::Indices;
    let x = puma_pool(5);
    for seed in 0..20u64 {
        let d = activecal::select::random_design(
            &mut design_rng(seed, 0),
            &(0..x.n_poses()).collect::<Vec<_>>(),
            &[],
            30,
        );
        let ind = Indices::from_design(&x, &d);
        let chol = design_ln_det(&x, None, &d).unwrap();
        assert_eq!(ind.rank, 27);
        assert!(
            (ind.ln_oid - chol).abs() <= 1e-10 * chol.abs(),
            "seed {seed}: {} vs {chol}",
            ind.ln_oid
        );
        // OI_D = ((OI·L)^L)², in logs.
        assert!((2.0 * 27.0 * (ind.oi * 27.0).ln() - ind.ln_oid).abs() < 1e-9);
    }
}

/// Multi-start keeps the start with the best score of the criterion that
/// drove it; with the D criterion that score is ln OI_D, so the result is
/// the one ranked by ln det.
#[test]
fn multistart_ranks_starts_by_the_criterion_score() {
    use activecal::criterion::{Criterion, InfoState, StateSettings};
    let x = puma_pool(3);
    let s = Settings::builder()
        .n(15)
        .initial(10)
        .starts(4)
        .seed(3)
        .build()
        .unwrap();
    let d = multistart(&x, DCriterion::new, Algorithm::Eae, &s).unwrap();
    assert_eq!(d.start_score, d.start_ln_oid);
    assert_eq!(d.score, d.ln_oid);
    let best = d
        .start_ln_oid
        .iter()
        .cloned()
        .fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(d.start_ln_oid[d.start], best);
    assert_eq!(d.start_score.len(), 4);

    let o = multistart(&x, OiCriterion::new, Algorithm::Eae, &s).unwrap();
    let best = o
        .start_score
        .iter()
        .cloned()
        .fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(o.start_score[o.start], best);
    assert_eq!(o.score, best);
    // The score is the criterion's own, recomputed from the design.
    let state = InfoState::new(&x, &o.poses, StateSettings::default()).unwrap();
    let again = OiCriterion::new().score(&x, &state);
    assert!(
        (again - o.score).abs() <= 1e-9 * again.abs(),
        "{again} vs {}",
        o.score
    );
}

#[test]
fn iterated_local_search_ends_at_a_local_optimum_above_its_start() {
    // On the 729-pose pool, N = 12: the search must (1) never end below the
    // plain multi-start it begins from (it keeps only improvements), (2) end
    // where no single (out, in) swap improves ln det (brute force, each swap
    // recomputed from scratch), (3) keep fixed poses, and (4) give the same
    // design and trace on 1 and 3 threads.
    let x = puma_pool(3);
    let plain = Settings::builder()
        .n(12)
        .starts(2)
        .seed(3)
        .fixed(vec![0, 400])
        .build()
        .unwrap();
    let s = plain.clone().into_builder().ils(6).build().unwrap();
    let run = |threads: usize, s: &Settings| {
        on_threads(threads, || {
            multistart(&x, DCriterion::new, Algorithm::Eae, s).unwrap()
        })
    };
    let a = run(1, &s);
    let b = run(3, &s);
    assert_eq!(a.poses, b.poses);
    assert_eq!(a.trace, b.trace);
    let p = run(1, &plain);
    assert!(a.ln_oid >= p.ln_oid - 1e-9, "{} < {}", a.ln_oid, p.ln_oid);
    assert!(a.poses.contains(&0) && a.poses.contains(&400));
    assert_eq!(a.trace.last().unwrap().ln_oid, a.ln_oid);
    let base = design_ln_det(&x, None, &a.poses).unwrap();
    assert!((base - a.ln_oid).abs() < 1e-6);
    assert_no_improving_swap(&x, &a.poses, &[0, 400]);
}

/// `select --noise` without `--report` prints the error predicted after
/// calibrating with the chosen poses: σ times a figure of the design alone
/// (the covariance σ²(XᵀX)⁻¹ carried to random configurations), so twice
/// the noise predicts exactly twice the error, and the figure is the
/// report's for the same design (`verify/tests/live_truth.rs` checks it
/// against the truth).
#[test]
fn select_predicts_the_calibrated_error_for_a_noise() {
    let run = |noise: &str| {
        super::common::json_of(&[
            "select", "--robot", "ur5", "--levels", "4", "--n", "30", "--noise", noise, "--json",
        ])
    };
    let (a, b) = (run("1e-4"), run("2e-4"));
    assert_eq!(a["poses"], b["poses"]);
    let f = |v: &serde_json::Value| v["predicted"]["position_rms_mm"].as_f64().unwrap();
    assert!(f(&a) > 0.0 && f(&a) < 1.0, "{}", f(&a));
    assert!((f(&b) / f(&a) - 2.0).abs() < 1e-12, "{} {}", f(&a), f(&b));
    assert_eq!(a["predicted"]["configurations"], 1000);
    assert_eq!(a["predicted"]["noise_m"], 1e-4);
}

/// `select --out` is repeatable: one run writes each format, the same
/// design in each; a path given twice (two outputs naming one file) is
/// refused before any work.
#[test]
fn select_writes_several_formats_in_one_run() {
    let dir = super::common::scratch_dir("select", "outs");
    let (csv, json) = (dir.join("d.csv"), dir.join("d.json"));
    let out = super::common::run(&[
        "select",
        "--robot",
        "ur5",
        "--levels",
        "3",
        "--n",
        "30",
        "--out",
        csv.to_str().unwrap(),
        "--out",
        json.to_str().unwrap(),
        "--force",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let design: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let rows = std::fs::read_to_string(&csv).unwrap().lines().count();
    assert_eq!(rows, 1 + design["poses"].as_array().unwrap().len());
    super::common::fails_with(
        &[
            "select",
            "--robot",
            "ur5",
            "--levels",
            "3",
            "--out",
            json.to_str().unwrap(),
            "--out",
            json.to_str().unwrap(),
            "--force",
        ],
        "--out and --out name the same file",
    );
}

/// A stuck pose's replacements (`select::swap`) are ranked by the design's
/// ln OI_D after the exchange, priced by the determinant lemma on the
/// design without the pose: each equals `design_ln_det` of the exchanged
/// design recomputed from scratch (to 1e-9 of a ln det of O(100): the
/// lemma's rounding), they come best first, and the first is the best
/// exchange of that pose over the whole pool.
#[test]
fn replacements_of_a_pose_are_ranked_by_the_ln_det_they_keep() {
    let x = puma_pool(3);
    let design: Vec<usize> = (0..30).map(|k| (k * 97 + 13) % x.n_poses()).collect();
    let k = 4;
    let ranked = activecal::select::swap::ranked_replacements(&x, None, &design, k, 8);
    assert_eq!(ranked.len(), 8);
    for w in ranked.windows(2) {
        assert!(w[0].1 >= w[1].1, "{ranked:?}");
    }
    let with = |c: usize| {
        let mut d = design.clone();
        d[k] = c;
        design_ln_det(&x, None, &d).unwrap()
    };
    for &(c, l) in &ranked {
        assert!(!design.contains(&c));
        assert!(
            (with(c) - l).abs() < 1e-9 * l.abs(),
            "{c}: {l} vs {}",
            with(c)
        );
    }
    let best = (0..x.n_poses())
        .filter(|i| !design.contains(i))
        .map(with)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!((best - ranked[0].1).abs() < 1e-9 * best.abs());
}
