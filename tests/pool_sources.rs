//! Pool sources: uniform random and Sobol samples inside the joint limits,
//! configurations from CSV and JSON files, and what each filter removed.

use activecal::measure::Visibility;
use activecal::model::Robot;
use activecal::pool::{PoolFilter, PoolSource, PoolSpec, Sobol};
use rand::{RngExt, SeedableRng};
use std::path::{Path, PathBuf};

fn build_with_threads(spec: &PoolSpec, robot: &Robot, threads: usize) -> activecal::pool::Pool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| spec.build(robot, &robot.nominal).unwrap())
}

fn within_limits(robot: &Robot, q: &[f64]) -> bool {
    q.iter()
        .zip(&robot.limits)
        .all(|(v, [lo, hi])| *lo <= *v && *v <= *hi)
}

#[test]
fn random_pool_is_the_seeded_stream_whatever_the_thread_count() {
    let r = Robot::puma560();
    let spec = PoolSpec::of(PoolSource::Random {
        count: 500,
        seed: 3,
    });
    let one = build_with_threads(&spec, &r, 1);
    let two = build_with_threads(&spec, &r, 2);
    assert_eq!(one.configs(), two.configs());
    assert_eq!(one.ids, (0..500).collect::<Vec<_>>());
    // Independently: the first 500·6 draws of ChaCha8 seeded with 3, in
    // order, mapped onto the limits — onto one turn from the lower limit
    // for joint 6, whose −176°..356° spans more than a turn (issue 27:
    // every angle drawn with the same density; the lattice keeps its even
    // levels, which are distinct angles).
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let ranges: Vec<[f64; 2]> = r
        .limits
        .iter()
        .map(|&l| activecal::pool::turn::sampling_range(true, l))
        .collect();
    assert_eq!(ranges[5][1], ranges[5][0] + std::f64::consts::TAU);
    for k in 0..500 {
        for (j, &[lo, hi]) in ranges.iter().enumerate() {
            let u: f64 = rng.random();
            let expect = lo * (1.0 - u) + hi * u;
            assert_eq!(one.config(k)[j], expect, "sample {k} joint {j}");
        }
        assert!(within_limits(&r, one.config(k)));
    }
    let other = PoolSpec::of(PoolSource::Random {
        count: 500,
        seed: 4,
    })
    .build(&r, &r.nominal)
    .unwrap();
    assert_ne!(other.config(0), one.config(0));
}

fn fixture(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

#[test]
fn sobol_matches_scipy_joe_kuo_points() {
    let text =
        std::fs::read_to_string(fixture("fixtures/sobol/scipy_unscrambled_21d_64.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let points = v["points"].as_array().unwrap();
    let s = Sobol::unit_cube(21, 64, None).unwrap();
    for (k, row) in points.iter().enumerate() {
        let expect: Vec<u32> = row
            .as_array()
            .unwrap()
            .iter()
            .map(|x| u32::try_from(x.as_u64().unwrap()).unwrap())
            .collect();
        assert_eq!(s.unit_point(k), expect, "point {k}");
    }
    assert!(Sobol::unit_cube(22, 8, None).is_err());
}

/// The first 2^m points of a (scrambled or plain) Sobol sequence put exactly
/// one point in each of the 2^m equal intervals of every coordinate, and in
/// each of the 2^a × 2^(m−a) boxes of the first two coordinates (their
/// t-value is 0). A wrong direction number or a scramble that is not
/// lower triangular breaks this.
#[test]
fn sobol_points_are_stratified_scrambled_or_not() {
    let m = 8;
    let n = 1usize << m;
    for seed in [None, Some(1), Some(7), Some(12345)] {
        let s = Sobol::unit_cube(10, n, seed).unwrap();
        let pts: Vec<Vec<u32>> = (0..n).map(|k| s.unit_point(k)).collect();
        for d in 0..10 {
            let mut hit = vec![false; n];
            for p in &pts {
                let cell = (p[d] >> (32 - m)) as usize;
                assert!(
                    !hit[cell],
                    "seed {seed:?} dim {d}: two points in cell {cell}"
                );
                hit[cell] = true;
            }
        }
        for a in 0..=m {
            let mut hit = vec![false; n];
            for p in &pts {
                let x = if a == 0 {
                    0
                } else {
                    (p[0] >> (32 - a)) as usize
                };
                let y = if a == m {
                    0
                } else {
                    (p[1] >> (32 - (m - a))) as usize
                };
                let cell = (x << (m - a)) | y;
                assert!(!hit[cell], "seed {seed:?}, 2^{a} x 2^{}: box {cell}", m - a);
                hit[cell] = true;
            }
        }
    }
    // Seeds scramble differently; the same seed gives the same points.
    let a = Sobol::unit_cube(6, 16, Some(1)).unwrap();
    let b = Sobol::unit_cube(6, 16, Some(2)).unwrap();
    let c = Sobol::unit_cube(6, 16, Some(1)).unwrap();
    assert_ne!(a.unit_point(3), b.unit_point(3));
    assert_eq!(a.unit_point(3), c.unit_point(3));
}

#[test]
fn sobol_pool_is_inside_the_limits_and_thread_independent() {
    let r = Robot::puma560();
    let spec = PoolSpec::of(PoolSource::Sobol {
        count: 300,
        seed: Some(9),
    });
    let one = build_with_threads(&spec, &r, 1);
    let two = build_with_threads(&spec, &r, 2);
    assert_eq!(one.configs(), two.configs());
    for k in 0..one.len() {
        assert!(within_limits(&r, one.config(k)));
    }
    // The spec round-trips through JSON.
    let text = serde_json::to_string(&spec).unwrap();
    let back: PoolSpec = serde_json::from_str(&text).unwrap();
    assert_eq!(back.source, spec.source);
}

fn temp_file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("activecal-pool-src-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn err_of(spec: &PoolSpec, r: &Robot) -> String {
    spec.build(r, &r.nominal).unwrap_err().to_string()
}

fn file_spec(p: &Path) -> PoolSpec {
    PoolSpec::of(PoolSource::File {
        path: p.display().to_string(),
    })
}

#[test]
fn csv_columns_are_matched_by_name_in_any_order() {
    let r = Robot::puma560();
    // Built-in arms name joints by frame label (0..5) or q1..q6.
    let p = temp_file(
        "shuffled.csv",
        "x,q6,q5,q4,q3,q2,q1,stamp\n\
         9,0.6,0.5,0.4,0.3,0.2,0.1,17\n\
         \n\
         9,-0.6,-0.5,-0.4,-0.3,-0.2,-0.1,18\n",
    );
    let pool = file_spec(&p).build(&r, &r.nominal).unwrap();
    assert_eq!(pool.len(), 2);
    assert_eq!(pool.config(0), &[0.1, 0.2, 0.3, 0.4, 0.5, 0.6]);
    assert_eq!(pool.config(1), &[-0.1, -0.2, -0.3, -0.4, -0.5, -0.6]);
    assert_eq!(pool.ids, vec![0, 1]);
    assert!(
        pool.stats.notes.iter().any(|n| n.contains("x, stamp")),
        "{:?}",
        pool.stats.notes
    );
}

#[test]
fn bad_configuration_files_name_file_row_and_column() {
    let r = Robot::puma560();
    let missing = temp_file("missing.csv", "q1,q2,q3,q4,q6\n0,0,0,0,0\n");
    let e = err_of(&file_spec(&missing), &r);
    assert!(e.contains("missing.csv") && e.contains("joint 5"), "{e}");
    // Line 3 (1-based, header on line 1), column q3, beyond the limits.
    let out = temp_file("out.csv", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n0,0,99,0,0,0\n");
    let e = err_of(&file_spec(&out), &r);
    assert!(
        e.contains("out.csv") && e.contains("line 3") && e.contains("'q3'") && e.contains("limits"),
        "{e}"
    );
    let nan = temp_file("nan.csv", "q1,q2,q3,q4,q5,q6\n0,0,0,NaN,0,0\n");
    let e = err_of(&file_spec(&nan), &r);
    assert!(
        e.contains("line 2") && e.contains("'q4'") && e.contains("finite"),
        "{e}"
    );
    let text = temp_file("text.csv", "q1,q2,q3,q4,q5,q6\n0,0,0,zero,0,0\n");
    let e = err_of(&file_spec(&text), &r);
    assert!(e.contains("line 2") && e.contains("'zero'"), "{e}");
    let short = temp_file("short.csv", "q1,q2,q3,q4,q5,q6\n0,0,0\n");
    assert!(err_of(&file_spec(&short), &r).contains("line 2"));
    let empty = temp_file("empty.csv", "q1,q2,q3,q4,q5,q6\n");
    assert!(err_of(&file_spec(&empty), &r).contains("no joint configurations"));
    let json_nan = temp_file("nan.json", r#"{"qs": [[0,0,0,0,0,0],[0,null,0,0,0,0]]}"#);
    let e = err_of(&file_spec(&json_nan), &r);
    assert!(e.contains("qs[1] (row 2)") && e.contains("joint 2"), "{e}");
    let nofile = PathBuf::from("/nonexistent/poses.csv");
    assert!(err_of(&file_spec(&nofile), &r).contains("/nonexistent/poses.csv"));
}

#[test]
fn json_configurations_in_joint_order_or_named() {
    let r = Robot::puma560();
    let plain = temp_file("plain.json", r#"{"qs": [[0.1,0.2,0.3,0.4,0.5,0.6]]}"#);
    let pool = file_spec(&plain).build(&r, &r.nominal).unwrap();
    assert_eq!(pool.config(0), &[0.1, 0.2, 0.3, 0.4, 0.5, 0.6]);
    let named = temp_file(
        "named.json",
        r#"{"joints": ["q2","q1","q3","q4","q5","q6","gripper"],
            "qs": [[0.2,0.1,0.3,0.4,0.5,0.6,0.01]], "points": [[1,2,3]]}"#,
    );
    let pool = file_spec(&named).build(&r, &r.nominal).unwrap();
    assert_eq!(pool.config(0), &[0.1, 0.2, 0.3, 0.4, 0.5, 0.6]);
    let notes = pool.stats.notes.join(" | ");
    assert!(
        notes.contains("gripper") && notes.contains("points"),
        "{notes}"
    );
    let wrong_robot = temp_file("robot.json", r#"{"robot": "ur5", "qs": [[0,0,0,0,0,0]]}"#);
    assert!(err_of(&file_spec(&wrong_robot), &r).contains("'ur5'"));
}

#[test]
fn filter_stats_count_what_each_filter_removed() {
    let r = Robot::puma560();
    let base = activecal::kinematics::position(&r, &r.nominal, &[0.0; 6]);
    let cone = Visibility::Cone {
        apex: [0.0; 3],
        axis: [base.x, base.y, base.z],
        half_angle: 0.05,
        max_range: 100.0,
    };
    let everything = Visibility::Box {
        min: [-100.0; 3],
        max: [100.0; 3],
    };
    let spec = PoolSpec::of(PoolSource::Random {
        count: 2000,
        seed: 1,
    })
    .with_filter(PoolFilter::Visibility(everything))
    .with_filter(PoolFilter::Visibility(cone.clone()));
    let pool = spec.build(&r, &r.nominal).unwrap();
    let st = &pool.stats;
    assert_eq!(st.candidates, 2000);
    assert_eq!(st.filters[0].removed, 0);
    assert_eq!(st.filters[1].seen, 2000);
    assert!(st.filters[1].removed > 0 && st.kept > 0);
    assert_eq!(st.kept, pool.len());
    assert_eq!(st.candidates - st.filters[1].removed, st.kept);
    // Every kept pose passes; every removed id fails.
    let mut kept = vec![false; 2000];
    pool.ids.iter().for_each(|&i| kept[i] = true);
    let all = PoolSpec::of(spec.source.clone())
        .build(&r, &r.nominal)
        .unwrap();
    for (id, &k) in kept.iter().enumerate() {
        let p = activecal::kinematics::position(&r, &r.nominal, all.config(id));
        assert_eq!(cone.sees(&p), k, "id {id}");
    }
    // A filter that removes everything is named.
    let none = Visibility::Box {
        min: [1e3; 3],
        max: [2e3; 3],
    };
    let e = err_of(
        &PoolSpec::of(PoolSource::Sobol {
            count: 64,
            seed: None,
        })
        .with_filter(PoolFilter::Visibility(none)),
        &r,
    );
    assert!(e.contains("visibility filter removed every pose"), "{e}");
}
