//! ChArUco boards in OpenCV's legacy layout and JPEG images (issue #51).
//!
//! `fixtures/camera/charuco_legacy/`: 4 renders, 640 × 480, of an OpenCV
//! ChArUco board of 4 × 5 squares printed with `setLegacyPattern(true)`
//! (`fixtures/camera/charuco_legacy_4x5.yaml`; `camera_images.py render
//! --charuco 4,5,0.025,0.018 --legacy --count 4 --far 0 --seed 5 --noise 0
//! --near-range 0.3,0.5` on a true UR5's flange camera, squares 23–41 px),
//! the true pixel of each corner in `fixtures/camera/charuco_legacy_truth.csv`.
//! `fixtures/camera/jpeg/`: the first two renders of
//! `fixtures/camera/images/` (320 × 240, a 6 × 9 checkerboard) saved as
//! JPEG at quality 90 by OpenCV.

use activecal::io::camera_info::read_camera_info;
use activecal::io::camera_target::read_target;
use activecal::io::images::joints::read_image_joints;
use activecal::io::images::{ImageObservations, read_images};
use std::collections::BTreeMap;
use std::path::Path;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The images of `dir` (from the repository's root) read with its
/// joints.csv, for the camera `info` and the target `target`.
fn read(dir: &str, info: &str, target: &str) -> activecal::error::Result<ImageObservations> {
    let robot = activecal::io::load_robot(&format!(
        "{}#tip=target",
        root().join("fixtures/ur5.urdf").display()
    ))
    .unwrap();
    let intrinsics = read_camera_info(&root().join(info)).unwrap();
    let target = read_target(&root().join(target)).unwrap();
    let dir = root().join(dir);
    let joints = read_image_joints(&dir.join("joints.csv"), &robot, Default::default()).unwrap();
    read_images(&dir, &joints, &target, &intrinsics)
}

/// The true pixels of a truth CSV (`pose, <joints…>, feature, u, v`), by
/// pose and feature.
fn truth(csv: &str) -> BTreeMap<(i64, usize), [f64; 2]> {
    let text = std::fs::read_to_string(root().join(csv)).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let (pose, feature, u, v) = (col("pose"), col("feature"), col("u"), col("v"));
    lines
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (
                (c[pose].parse().unwrap(), c[feature].parse().unwrap()),
                [c[u].parse().unwrap(), c[v].parse().unwrap()],
            )
        })
        .collect()
}

/// Each corner found's distance to its true pixel, px, sorted.
fn errors(read: &ImageObservations, truth: &BTreeMap<(i64, usize), [f64; 2]>) -> Vec<f64> {
    let mut e = Vec::new();
    for (i, id) in read.observations.pose_ids.iter().enumerate() {
        for (k, p) in read.observations.seen[i].iter().enumerate() {
            if let Some(p) = p {
                let t = truth[&(*id, k)];
                e.push((p[0] - t[0]).hypot(p[1] - t[1]));
            }
        }
    }
    e.sort_by(f64::total_cmp);
    e
}

const LEGACY: &str = "fixtures/camera/charuco_legacy";
const CHARUCO_INFO: &str = "fixtures/camera/charuco_camera_info.yaml";

/// Every corner of the legacy board found in every render, each with the
/// id of its true place: another id is a square (≥ 23 px) away, so the
/// bounds of the current layout's fixture test (the detector's corners
/// within 0.5 px of the truth, refined ones within 0.1 px in the median
/// on noise-free renders) tell a right id from a wrong one.
#[test]
fn legacy_charuco_corners_found_in_the_committed_renders_carry_the_true_ids() {
    let r = read(
        LEGACY,
        CHARUCO_INFO,
        "fixtures/camera/charuco_legacy_4x5.yaml",
    )
    .unwrap();
    let e = errors(&r, &truth("fixtures/camera/charuco_legacy_truth.csv"));
    let (median, max) = (e[e.len() / 2], e[e.len() - 1]);
    println!(
        "{} corners of 4 × 12: {median:.3} px median, {max:.3} px max",
        e.len()
    );
    assert_eq!(r.observations.pose_ids, vec![0, 1, 2, 3]);
    assert_eq!(e.len(), 4 * 12);
    assert!(median < 0.1, "median {median} px");
    assert!(max < 0.5, "max {max} px");
}

/// A board read with the other layout than the one it was printed in:
/// every image is left out saying which layout its markers are, so no
/// corner is used with another corner's id: the legacy renders given as
/// the current layout, and the current layout's renders
/// (`fixtures/camera/charuco/`) given as legacy.
#[test]
fn a_charuco_board_in_the_other_layout_is_refused_saying_which() {
    let cases = [
        (
            LEGACY,
            "fixtures/camera/charuco_4x5.yaml",
            "the markers read are those of OpenCV's legacy layout: is the board printed with setLegacyPattern(true)? say `legacy_pattern: true`",
        ),
        (
            "fixtures/camera/charuco",
            "fixtures/camera/charuco_legacy_4x5.yaml",
            "the markers read are those of OpenCV's current layout (4.6 and later): is the board printed without setLegacyPattern(true)? remove `legacy_pattern: true`",
        ),
    ];
    for (dir, target, says) in cases {
        let e = read(dir, CHARUCO_INFO, target).unwrap_err().to_string();
        assert!(e.contains("no image could be used"), "{dir}: {e}");
        for k in 0..4 {
            let line = e
                .lines()
                .find(|l| l.trim_start().starts_with(&format!("img_{k:03}.png:")))
                .unwrap_or_else(|| panic!("{dir}: img_{k:03}.png not listed in {e}"));
            assert!(line.contains(says), "{dir}: {line}");
        }
    }
}

/// The check has evidence on every committed ChArUco render read with
/// its own layout: at least 3 markers read on and around the board, each
/// where the layout puts it, and every square without a marker seen dark
/// (the counts printed are the measurement in docs/cameras.md).
#[test]
fn every_marker_read_on_the_committed_renders_is_where_their_layout_puts_it() {
    for (dir, target) in [
        (
            "fixtures/camera/charuco",
            "fixtures/camera/charuco_4x5.yaml",
        ),
        (LEGACY, "fixtures/camera/charuco_legacy_4x5.yaml"),
    ] {
        let counts = marker_counts(
            &root().join(dir),
            &root().join(CHARUCO_INFO),
            &root().join(target),
        );
        assert_eq!(counts.len(), 4);
        for (f, c) in counts {
            let (agree, disagree, white) = c.unwrap_or_else(|e| panic!("{dir}/{f}: {e}"));
            println!(
                "{dir}/{f}: {agree} markers agree, {disagree} disagree, {white:?} plain squares not black"
            );
            assert!(
                agree >= 3 && disagree == 0,
                "{dir}/{f}: {agree} agree, {disagree} disagree"
            );
            assert_eq!(white, Some(0), "{dir}/{f}");
        }
    }
}

/// The JPEG files (quality 90) of two renders give the corners of their
/// PNGs: the same ids, each within 0.1 px of the PNG's. The bound: the
/// JPEG's pixels differ from the PNG's by its quantisation (measured with
/// OpenCV's decoder: 0.88 grey levels RMS, 12 at most); a corner is the
/// least-squares meeting point of the edges' gradients over its window,
/// whose error from a zero-mean difference of σ levels is about σ /
/// (contrast · √(pixels in the window)) px: 0.88 / (165 · 3) ≈ 0.002 px
/// for the smallest window here (3 × 3 px in squares of 6–13 px, black 81
/// and white 246), and 0.88 / 165 · 8 ≈ 0.04 px if the difference were
/// one value over a JPEG block of 8 px (no averaging at all): under 0.1
/// px either way.
#[test]
fn jpeg_images_give_the_corners_of_their_pngs() {
    let jpeg = read(
        "fixtures/camera/jpeg",
        "fixtures/camera/small_camera_info.yaml",
        "fixtures/camera/board_6x9.yaml",
    )
    .unwrap();
    let png = read(
        "fixtures/camera/images",
        "fixtures/camera/small_camera_info.yaml",
        "fixtures/camera/board_6x9.yaml",
    )
    .unwrap();
    assert_eq!(jpeg.observations.pose_ids, vec![0, 1]);
    let mut worst: f64 = 0.0;
    for k in 0..2 {
        let (a, b) = (&jpeg.observations.seen[k], &png.observations.seen[k]);
        assert_eq!(a.len(), b.len());
        for (p, q) in a.iter().zip(b) {
            let (Some(p), Some(q)) = (p, q) else {
                panic!("image {k}: a corner found in one and not the other");
            };
            worst = worst.max((p[0] - q[0]).hypot(p[1] - q[1]));
        }
    }
    println!("JPEG against PNG: {worst:.3} px at most");
    assert!(worst < 0.1, "{worst} px");
}

/// Each image's markers read on and around the board against its layout
/// (the check of `activecal::io::images::layout`), from the corners the
/// detector labelled: `(file, (agree, disagree, squares without a marker
/// not black))`, or the reason the image was refused.
fn marker_counts(
    dir: &Path,
    info: &Path,
    target: &Path,
) -> Vec<(String, Result<(usize, usize, Option<usize>), String>)> {
    use activecal::io::images::{
        charuco::find_charuco, decode::decode_image, files::image_files, layout,
    };
    let t = read_target(target).unwrap();
    let p = t.charuco.clone().unwrap();
    let _ = read_camera_info(info).unwrap();
    let dictionary =
        calib_targets_aruco::resolve_dictionary(p.dictionary.as_deref().unwrap()).unwrap();
    let lay = layout::Layout::opencv(p.rows, p.cols, p.legacy_pattern);
    image_files(dir)
        .unwrap()
        .iter()
        .map(|f| {
            let img = decode_image(&std::fs::read(f).unwrap()).unwrap();
            let name = f.file_name().unwrap().to_string_lossy().into_owned();
            let counts = find_charuco(&img, &p).map(|found| {
                let inner = p.cols - 1;
                let corners = found
                    .iter()
                    .map(|c| ([(c.id % inner + 1) as i64, (c.id / inner + 1) as i64], c.px))
                    .collect();
                let grid = layout::Grid::new(&corners).unwrap();
                let rel = p.marker / p.square;
                let reads = layout::read_markers(&img, &grid, (p.rows, p.cols), dictionary, rel);
                let a = layout::agreement(&lay, &reads);
                let white = layout::white_where_black(&img, &grid, &lay, rel);
                (a.agree, a.disagree, white)
            });
            (name, counts)
        })
        .collect()
}

/// The measurement behind the check's rule (docs/cameras.md), not a gate:
/// `MEASURE='DIR,CAMERA_INFO,TARGET;…' cargo test --test all --
/// camera_legacy::measure --ignored --nocapture` prints each image's
/// counts (agree, disagree, plain squares not black) or its reason.
#[test]
#[ignore]
fn measure_marker_counts() {
    let spec = std::env::var("MEASURE").unwrap_or_default();
    for case in spec.split(';').filter(|c| !c.is_empty()) {
        let v: Vec<&str> = case.split(',').collect();
        for (f, c) in marker_counts(Path::new(v[0]), Path::new(v[1]), Path::new(v[2])) {
            println!("MEASURE {} {} {f} {c:?}", v[0], v[2]);
        }
    }
}
