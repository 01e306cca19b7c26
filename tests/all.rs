//! Every integration test, in one test binary: one build and one link of
//! the library for all of them (each file under `tests/` used to be a binary
//! of its own, linked 40-odd times), and one process whose test threads
//! share the machine's cores across files. Each file is a module; a new
//! test file is added to the list below (`every_test_file_is_a_module`
//! fails until it is). Run one file's tests with
//! `cargo test --test all FILE::`.

mod common;

mod atomic_writes;
mod bad_inputs;
mod bags;
mod bound;
mod camera;
mod camera_cli;
mod camera_fisheye;
mod camera_head;
mod camera_images;
mod camera_labels;
mod camera_legacy;
mod camera_messy;
mod camera_refuse;
mod camera_sight;
mod camera_start;
mod cli;
mod cli_contacts;
mod cli_existing;
mod cli_operator;
mod cli_pools;
mod cli_progress;
mod cli_robots;
mod cli_safety;
mod collision;
mod compliance;
mod contact_export;
mod docs_examples;
mod erd_fixtures;
mod export_fixtures;
mod fixtures;
mod frames;
mod fuzz_loaders;
mod gravity_fixtures;
mod house;
mod identifiability;
mod identification_jacobian_fixtures;
mod identify;
mod jacobian;
mod json_shape;
mod kinematics_files;
mod licences;
mod mesh_formats;
mod options;
mod output_overlap;
mod page_browser;
mod paper_golden;
mod plane_contacts;
mod point_coincidence;
mod pool_sources;
mod prior;
mod real_data;
mod refine;
mod reports;
mod reproduce;
mod robots;
mod robots_describe;
mod score_design;
mod seam_commands;
mod seam_sensor;
mod select;
mod tour_moves;
mod truth_fixtures;
mod undetermined;
mod unit_invariance;
mod units;
mod urdf_chains;
mod wrong_inputs;

/// Every `tests/*.rs` file is one of the modules above: a file left out
/// would silently never run.
#[test]
fn every_test_file_is_a_module() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    // The root crate's, the property tests' and verify's test binaries.
    for crate_dir in [".", "proptests", "verify"] {
        let tests = root.join(crate_dir).join("tests");
        let all = std::fs::read_to_string(tests.join("all.rs")).expect("tests/all.rs is readable");
        // A listed module: `mod NAME;`, possibly behind a `#[cfg(..)]` line.
        let listed: Vec<&str> = all
            .lines()
            .filter_map(|l| l.trim().strip_prefix("mod ")?.strip_suffix(';'))
            .collect();
        let mut missing = Vec::new();
        for e in std::fs::read_dir(&tests).expect("tests/ is readable") {
            let name = e.expect("a directory entry").file_name();
            let name = name.to_string_lossy();
            if let Some(stem) = name.strip_suffix(".rs")
                && stem != "all"
                && !listed.contains(&stem)
            {
                missing.push(stem.to_string());
            }
        }
        assert!(
            missing.is_empty(),
            "{crate_dir}/tests/all.rs does not list {missing:?}"
        );
    }
}
