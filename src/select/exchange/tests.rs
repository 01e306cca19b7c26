//! The exchange algorithms on small random pools (30 poses, `t = 2`,
//! `p = 4`), checked against a direct evaluation of every design
//! ([`design_ln_det`], a Cholesky of `XᵀX` from scratch) and by brute
//! force over all single swaps.
use super::*;
use crate::criterion::{DCriterion, design_ln_det};
use crate::select::{StepKind, design_rng};
use faer::Mat;

/// The searches accept a step that raises `ln det` by more than
/// `TOL·max(|ln det|, 1)` (1e-10 here, `ln det` ≈ 5); the updated values
/// differ from a direct evaluation by ~1e-13 on these well-conditioned
/// 4 × 4 problems. 1e-8 covers both and is far below any real
/// improvement of a swap (≥ 1e-3 on a random pool).
const EPS: f64 = 1e-8;

fn pool(seed: u64) -> Blocks {
    let mut s = seed;
    Blocks::new(
        Mat::from_fn(60, 4, |_, _| crate::linalg::test_rng::lcg(&mut s)),
        2,
    )
}

fn settings() -> Settings {
    Settings::builder().n(6).initial(3).build().unwrap()
}

fn ln_det(x: &Blocks, poses: &[usize]) -> f64 {
    design_ln_det(x, None, poses).expect("a regular design")
}

/// No swap of a design pose (other than `fixed`) for a pool pose
/// outside the design raises `ln det` by more than `EPS`.
fn assert_swap_optimal(x: &Blocks, poses: &[usize], fixed: &[usize]) {
    let base = ln_det(x, poses);
    for k in 0..poses.len() {
        for i in (0..x.n_poses()).filter(|i| !poses.contains(i)) {
            let mut d = poses.to_vec();
            d[k] = i;
            if let (false, Some(v)) = (fixed.contains(&poses[k]), design_ln_det(x, None, &d)) {
                assert!(v <= base + EPS, "swap {k}->{i}: {base} to {v}");
            }
        }
    }
}

/// A finished selection reports its own design: `N` distinct poses,
/// `ln OI_D` and the D criterion's score equal to a direct evaluation,
/// `oi` from it; its trace replays from `trace_initial` step by step,
/// each row's size and (ridge-free) `ln OI_D` that of the design after
/// it, and ends at the design.
fn assert_consistent(x: &Blocks, sel: &Selection, n: usize) {
    let mut sorted = sel.poses.clone();
    sorted.sort_unstable();
    sorted.dedup();
    assert_eq!(sorted.len(), n, "{:?}", sel.poses);
    let direct = ln_det(x, &sel.poses);
    assert!(
        (sel.ln_oid - direct).abs() < EPS,
        "{} vs {direct}",
        sel.ln_oid
    );
    assert!((sel.score - direct).abs() < EPS);
    assert_eq!(sel.oi, oi_from_ln_oid(sel.ln_oid, x.p()));
    assert_eq!(sel.criterion, DCriterion::new().name());
    let mut d = sel.trace_initial();
    for (k, row) in sel.trace.iter().enumerate() {
        assert_eq!(row.step, k);
        if let Some(r) = row.removed {
            d.retain(|&j| j != r);
        }
        if let Some(a) = row.added {
            d.push(a);
        }
        assert_eq!(row.size, d.len(), "row {k}");
        if !row.ridge {
            let v = ln_det(x, &d);
            assert!(
                (row.ln_oid - v).abs() < EPS,
                "row {k}: {} vs {v}",
                row.ln_oid
            );
        }
    }
    d.sort_unstable();
    assert_eq!(d, sorted);
    assert_eq!(sel.trace.last().map(|r| r.ln_oid), Some(sel.ln_oid));
}

/// An exchange is kept only if it raises the criterion: along every
/// trace, each exchange row's `ln OI_D` is above the row before it.
fn assert_exchanges_improve(sel: &Selection) {
    for w in sel.trace.windows(2) {
        if w[1].kind == StepKind::Exchange && !w[0].ridge {
            assert!(w[1].ln_oid > w[0].ln_oid, "{:?}", w);
        }
    }
}

#[test]
fn fedorov_ends_where_no_swap_improves() {
    for seed in 1..4 {
        let x = pool(seed);
        let s = settings();
        let sel = fedorov(&x, &mut DCriterion::new(), &s, &mut design_rng(seed, 0)).unwrap();
        assert_consistent(&x, &sel, 6);
        assert_exchanges_improve(&sel);
        assert_eq!(sel.algorithm, Algorithm::Fedorov);
        assert_eq!(sel.trace_initial().len(), 6);
        assert!(sel.trace.len() > 1, "no exchange from a random start");
        assert_swap_optimal(&x, &sel.poses, &[]);
    }
}

/// EAE: `n0` random poses, exchange steps, add steps up to `N`, exchange
/// steps; the paper's rule keeps adding while the criterion does not
/// fall, which for `ln det` is always.
#[test]
fn eae_grows_from_its_initial_design_to_n() {
    for seed in 1..4 {
        let x = pool(seed);
        let s = settings();
        let sel = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(seed, 0)).unwrap();
        assert_consistent(&x, &sel, 6);
        assert_exchanges_improve(&sel);
        assert_eq!(sel.algorithm, Algorithm::Eae);
        assert_eq!(sel.trace_initial().len(), 3);
        let adds = sel.trace.iter().filter(|r| r.kind == StepKind::Add).count();
        assert_eq!(adds, 3);
        // A regular start (6 rows for 4 unknowns) never had a ridge to drop.
        assert!(!sel.trace[0].ridge);
        assert!(sel.trace.iter().all(|r| r.kind != StepKind::DropRidge));
        assert_exchange_step_stopped(&x, &sel.poses);
        // The last exchange phase leaves no better (out, in) pair for
        // the pose whose removal costs least: at least not below the
        // start.
        assert!(sel.ln_oid > sel.trace[0].ln_oid);
    }
}

/// DETMAX ends when the pose just added is the one removed, with the
/// design back at `N` and never below its start.
#[test]
fn detmax_stops_when_the_added_pose_is_removed() {
    for seed in 1..4 {
        let x = pool(seed);
        let sel = detmax(
            &x,
            &mut DCriterion::new(),
            &settings(),
            &mut design_rng(seed, 0),
        )
        .unwrap();
        assert_consistent(&x, &sel, 6);
        let n = sel.trace.len();
        assert!(n >= 3);
        let (add, rem) = (&sel.trace[n - 2], &sel.trace[n - 1]);
        assert_eq!((add.kind, rem.kind), (StepKind::Add, StepKind::Remove));
        assert_eq!(add.added, rem.removed);
        assert!(sel.ln_oid >= sel.trace[0].ln_oid - EPS);
        // Each excursion adds the best pose and removes the least
        // useful: the removal row never ends below the row before the add.
        for k in (1..n - 1).filter(|&k| sel.trace[k].kind == StepKind::Add) {
            assert!(sel.trace[k + 1].ln_oid >= sel.trace[k - 1].ln_oid - EPS);
        }
    }
}

/// Fixed poses are in every design and no step removes them; a start
/// too small to be regular (one pose, 2 rows for 4 unknowns) runs on a
/// ridge that is dropped once the design is regular, and the result is
/// ridge-free.
#[test]
fn fixed_poses_stay_and_a_singular_start_runs_on_a_ridge() {
    let x = pool(5);
    let s = settings()
        .into_builder()
        .initial(1)
        .fixed(vec![7, 11])
        .build()
        .unwrap();
    for algorithm in [Algorithm::Eae, Algorithm::Fedorov, Algorithm::Detmax] {
        let sel = multistart(&x, DCriterion::new, algorithm, &s).unwrap();
        assert_consistent(&x, &sel, 6);
        assert!(
            sel.poses.contains(&7) && sel.poses.contains(&11),
            "{algorithm:?}"
        );
        assert!(
            sel.trace
                .iter()
                .all(|r| r.removed != Some(7) && r.removed != Some(11))
        );
        if algorithm == Algorithm::Fedorov {
            assert_swap_optimal(&x, &sel.poses, &[7, 11]);
        }
    }
    let sel = eae(
        &x,
        &mut DCriterion::new(),
        &s.clone().into_builder().fixed(vec![]).build().unwrap(),
        &mut design_rng(1, 0),
    )
    .unwrap();
    assert!(sel.trace[0].ridge, "a one-pose start is singular");
    let drops = sel
        .trace
        .iter()
        .filter(|r| r.kind == StepKind::DropRidge)
        .count();
    assert_eq!(drops, 1);
    assert!(!sel.trace.last().unwrap().ridge);
}

/// Multi-start keeps the start of highest score (the lowest on ties)
/// and reports every start's `ln OI_D` and score in start order; each
/// start is the single-start run of its own stream, so the kept one is
/// reproduced by `eae` on stream `start`.
#[test]
fn multistart_keeps_the_best_start() {
    let x = pool(2);
    // One exchange per phase, so that the starts end apart.
    let s = settings()
        .into_builder()
        .starts(5)
        .seed(9)
        .max_iter(1)
        .build()
        .unwrap();
    let sel = multistart(&x, DCriterion::new, Algorithm::Eae, &s).unwrap();
    assert_consistent(&x, &sel, 6);
    assert_eq!(sel.start_score.len(), 5);
    assert_eq!(sel.start_ln_oid, sel.start_score);
    let best = sel
        .start_score
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let first = sel.start_score.iter().position(|&v| v == best).unwrap();
    assert_eq!((sel.start, sel.score), (first, best));
    for k in 0..5 {
        let one = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(9, k as u64)).unwrap();
        assert_eq!(one.ln_oid, sel.start_ln_oid[k], "start {k}");
        if k == sel.start {
            assert_eq!(one.poses, sel.poses);
        }
    }
    assert!(
        sel.start_score.iter().any(|&v| v < best - 1e-3),
        "starts that all tie test no ranking: {:?}",
        sel.start_score
    );
}

/// The Fedorov polish continues the trace of the design it polishes,
/// never lowers it, ends where no swap improves, and keeps the
/// multi-start record.
#[test]
fn polish_continues_the_trace_to_a_swap_optimum() {
    let x = pool(3);
    let s = settings().into_builder().starts(2).build().unwrap();
    let plain = multistart(&x, DCriterion::new, Algorithm::Detmax, &s).unwrap();
    let polished = multistart(
        &x,
        DCriterion::new,
        Algorithm::Detmax,
        &s.clone().into_builder().polish(true).build().unwrap(),
    )
    .unwrap();
    assert_consistent(&x, &polished, 6);
    assert_eq!(polished.trace[..plain.trace.len()], plain.trace[..]);
    assert!(polished.ln_oid >= plain.ln_oid - EPS);
    assert_swap_optimal(&x, &polished.poses, &[]);
    assert_eq!(
        (polished.start, &polished.start_ln_oid, polished.algorithm),
        (plain.start, &plain.start_ln_oid, Algorithm::Detmax)
    );
}

/// Iterated local search starts from the algorithm's result and keeps
/// only improvements: never below the same start without it, and at a
/// swap optimum (its climbs are modified-Fedorov sweeps).
#[test]
fn iterated_local_search_ends_at_a_swap_optimum_above_its_start() {
    for seed in 1..4 {
        let x = pool(seed);
        let plain = settings();
        let s = plain.clone().into_builder().ils(4).kick(2).build().unwrap();
        let a = eae(&x, &mut DCriterion::new(), &plain, &mut design_rng(seed, 0)).unwrap();
        let b = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(seed, 0)).unwrap();
        assert_consistent(&x, &b, 6);
        assert!(b.ln_oid >= a.ln_oid - EPS, "{} < {}", b.ln_oid, a.ln_oid);
        assert_swap_optimal(&x, &b.poses, &[]);
    }
}

/// A pool that cannot determine every unknown (its last column zero):
/// every algorithm, random search included, refuses rather than return
/// a singular design.
#[test]
fn a_rank_deficient_pool_is_an_error() {
    let x = pool(4);
    let mut m = x.mat().to_owned();
    m.col_mut(3).fill(0.0);
    let x = Blocks::new(m, 2);
    let s = settings().into_builder().designs(20).build().unwrap();
    for algorithm in [
        Algorithm::Eae,
        Algorithm::Fedorov,
        Algorithm::Detmax,
        Algorithm::Random,
    ] {
        let e = multistart(&x, DCriterion::new, algorithm, &s).unwrap_err();
        assert!(e.to_string().contains("singular"), "{algorithm:?}: {e}");
    }
}

/// The random search reports its best design, evaluated afresh, with
/// the number of that design and its sample of `ln OI_D`, none above
/// the kept one.
#[test]
fn random_search_keeps_its_best_design() {
    let x = pool(6);
    let s = settings().into_builder().designs(40).build().unwrap();
    let sel = multistart(&x, DCriterion::new, Algorithm::Random, &s).unwrap();
    assert_consistent(&x, &sel, 6);
    assert_eq!(sel.algorithm, Algorithm::Random);
    assert!(sel.start < 40);
    assert!(!sel.start_ln_oid.is_empty());
    assert!(sel.start_ln_oid.iter().all(|&v| v <= sel.ln_oid + EPS));
}

/// `pool` with `n` poses.
fn pool_of(n: usize, seed: u64) -> Blocks {
    let mut s = seed;
    Blocks::new(
        Mat::from_fn(2 * n, 4, |_, _| crate::linalg::test_rng::lcg(&mut s)),
        2,
    )
}

/// Iterated local search keeps a round only if it improves: from the
/// global optimum (8 poses, `N = 6`, checked over all 28 designs) each
/// round's kick is climbed back from and undone, so the state and the
/// trace are those of the climb alone, whatever the rounds did.
#[test]
fn rounds_that_do_not_improve_are_undone() {
    let x = pool_of(8, 21);
    let start: Vec<usize> = (0..6).collect();
    let mut best = f64::NEG_INFINITY;
    for a in 0..8 {
        for b in a + 1..8 {
            let d: Vec<usize> = (0..8).filter(|&i| i != a && i != b).collect();
            best = best.max(ln_det(&x, &d));
        }
    }
    let mut crit = DCriterion::new();
    let mut climb = Run::new(&x, &mut crit, &start, &[], None).unwrap();
    climb.modified_fedorov_phase(MAX_SWEEPS);
    assert!(
        (climb.state.ln_det() - best).abs() < EPS,
        "the climb is not at the optimum"
    );
    let mut crit = DCriterion::new();
    let mut ils = Run::new(&x, &mut crit, &start, &[], None).unwrap();
    ils.iterated_phase(6, 2, 1000, &mut design_rng(1, 0));
    assert_eq!(ils.state.design(), climb.state.design());
    assert_eq!(ils.trace, climb.trace);
}

/// EAE's last phase stops where the paper's exchange step does: the
/// best exchange of the design pose whose removal costs least (brute
/// force) does not raise `ln det`.
fn assert_exchange_step_stopped(x: &Blocks, poses: &[usize]) {
    let without = |k: usize| {
        let d: Vec<usize> = poses.iter().copied().filter(|&j| j != poses[k]).collect();
        ln_det(x, &d)
    };
    let out = (0..poses.len())
        .max_by(|&a, &b| without(a).total_cmp(&without(b)))
        .unwrap();
    let base = ln_det(x, poses);
    for i in (0..x.n_poses()).filter(|i| !poses.contains(i)) {
        let mut d = poses.to_vec();
        d[out] = i;
        if let Some(v) = design_ln_det(x, None, &d) {
            assert!(
                v <= base + EPS,
                "exchange {}->{i}: {base} to {v}",
                poses[out]
            );
        }
    }
}

/// The kicks get past local optima of single exchanges, the point of
/// the search: over ten pools of 40 poses, from the first 6, it never
/// ends below the modified-Fedorov optimum it starts from, and some
/// search ends above it (by more than 1e-6, far above rounding). Both
/// the climb and the search end where no single swap improves.
#[test]
fn kicks_get_past_single_exchange_optima() {
    let mut above = 0;
    for seed in 0..10 {
        let x = pool_of(40, 50 + seed);
        let start: Vec<usize> = (0..6).collect();
        let mut crit = DCriterion::new();
        let mut climb = Run::new(&x, &mut crit, &start, &[], None).unwrap();
        climb.modified_fedorov_phase(MAX_SWEEPS);
        let mut crit = DCriterion::new();
        let mut ils = Run::new(&x, &mut crit, &start, &[], None).unwrap();
        ils.iterated_phase(8, 2, 1000, &mut design_rng(seed, 0));
        let (a, b) = (climb.state.ln_det(), ils.state.ln_det());
        assert!(b >= a - EPS, "pool {seed}: {b} < {a}");
        assert_swap_optimal(&x, climb.state.design(), &[]);
        assert_swap_optimal(&x, ils.state.design(), &[]);
        if b > a + 1e-6 {
            above += 1;
        }
    }
    assert!(above > 0, "no search left its local optimum");
}
