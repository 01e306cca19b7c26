//! ROS 2 bags (issue #52): the small committed bags of `fixtures/bags/`
//! (written by `rosbags`, `verify/python/bag_truth.py tiny`) read in both
//! storage formats, and bad bags refused with the reason, never a panic.
//! The truth tests (a simulated run, the clock offset, calibration) are
//! `verify/tests/live_bags.rs`.

use crate::common::{fails_with, json_of, run, scratch_dir};
use std::path::Path;

const UR5: &str = "fixtures/ur5.urdf";

/// The three rests `bag_truth.py tiny` drives the arm to (its `qs`).
const RESTS: [[f64; 6]; 3] = [
    [0.0, -1.2, 1.4, -1.7, -1.57, 0.0],
    [0.4, -1.0, 1.2, -1.5, -1.4, 0.3],
    [-0.3, -1.4, 1.6, -1.9, -1.7, -0.4],
];

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    (head, rows)
}

#[test]
fn mcap_and_sqlite_bags_give_the_rests_joint_values() {
    let d = scratch_dir("bags", "formats");
    for bag in ["fixtures/bags/tiny.mcap", "fixtures/bags/tiny_db3"] {
        let out = d.join("m.csv");
        let o = out.to_str().unwrap();
        let r = json_of(&[
            "extract", bag, "--robot", UR5, "--points", "/tracker", "--out", o, "--force", "--json",
        ]);
        assert_eq!(r["rests"].as_array().unwrap().len(), 3, "{bag}: {r}");
        let (head, rows) = read_csv(&out);
        assert_eq!(head[0], "shoulder_pan_joint", "{bag}");
        assert_eq!(&head[6..9], ["x1", "y1", "z1"], "{bag}");
        assert_eq!(rows.len(), 3, "{bag}");
        for (row, want) in rows.iter().zip(RESTS) {
            // The arm stands exactly still at each rest: the average is the
            // pose the generator drove it to.
            for (got, want) in row[..6].iter().zip(want) {
                assert!((got - want).abs() < 1e-12, "{bag}: {row:?} vs {want:?}");
            }
            // The made-up point of the generator: 0.5 + 0.1 q1, 0.2 q2,
            // 0.3 + 0.1 q3 with 0.01 mm of noise, averaged over 5–7 samples.
            let p = [0.5 + 0.1 * want[0], 0.2 * want[1], 0.3 + 0.1 * want[2]];
            for k in 0..3 {
                assert!((row[6 + k] - p[k]).abs() < 5e-5, "{bag}: {row:?}");
            }
        }
    }
}

#[test]
fn a_cut_short_mcap_or_db3_is_refused() {
    let d = scratch_dir("bags", "truncated");
    let bytes = std::fs::read("fixtures/bags/tiny.mcap").unwrap();
    let cut = d.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let c = cut.to_str().unwrap();
    fails_with(
        &["extract", c, "--robot", UR5, "--points", "/tracker"],
        "cut short",
    );
    let db = std::fs::read("fixtures/bags/tiny_db3/tiny_db3.db3").unwrap();
    let cut = d.join("cut.db3");
    std::fs::write(&cut, &db[..db.len() / 3]).unwrap();
    let c = cut.to_str().unwrap();
    fails_with(
        &["extract", c, "--robot", UR5, "--points", "/tracker"],
        "SQLite 3",
    );
    let empty = d.join("empty.mcap");
    std::fs::write(&empty, b"").unwrap();
    let e = empty.to_str().unwrap();
    fails_with(
        &["extract", e, "--robot", UR5, "--points", "/tracker"],
        "neither MCAP nor SQLite",
    );
}

#[test]
fn an_unknown_storage_plugin_is_named() {
    let d = scratch_dir("bags", "plugin");
    std::fs::write(
        d.join("metadata.yaml"),
        "rosbag2_bagfile_information:\n  version: 9\n  storage_identifier: rosbag_v1\n  relative_file_paths: [a.bag]\n",
    )
    .unwrap();
    let b = d.to_str().unwrap();
    fails_with(
        &["extract", b, "--robot", UR5, "--points", "/tracker"],
        "storage plugin 'rosbag_v1' is not read",
    );
}

#[test]
fn a_missing_topic_lists_the_bags_topics() {
    fails_with(
        &[
            "extract",
            "fixtures/bags/tiny.mcap",
            "--robot",
            UR5,
            "--points",
            "/nope",
        ],
        "no topic '/nope' (the bag's topics: /joint_states (sensor_msgs/msg/JointState), /tracker (geometry_msgs/msg/PointStamped), /camera_info (sensor_msgs/msg/CameraInfo))",
    );
    fails_with(
        &[
            "extract",
            "fixtures/bags/tiny_db3",
            "--robot",
            UR5,
            "--joints",
            "/js",
            "--points",
            "/tracker",
        ],
        "no topic '/js'",
    );
}

#[test]
fn a_topic_of_another_type_is_named_with_its_type() {
    fails_with(
        &[
            "extract",
            "fixtures/bags/tiny.mcap",
            "--robot",
            UR5,
            "--points",
            "/camera_info",
        ],
        "topic '/camera_info' is of type sensor_msgs/msg/CameraInfo, not geometry_msgs/msg/PointStamped",
    );
    fails_with(
        &[
            "extract",
            "fixtures/bags/tiny.mcap",
            "--robot",
            UR5,
            "--poses",
            "/tracker",
        ],
        "not geometry_msgs/msg/PoseStamped or geometry_msgs/msg/TransformStamped",
    );
    fails_with(
        &[
            "extract",
            "fixtures/bags/tiny.mcap",
            "--robot",
            UR5,
            "--tf",
            "world:tool",
        ],
        "no topic '/tf'",
    );
}

#[test]
fn a_joint_of_the_robot_absent_from_the_joint_states_is_named() {
    fails_with(
        &[
            "extract",
            "fixtures/bags/tiny.mcap",
            "--robot",
            "fixtures/stanford.urdf",
            "--points",
            "/tracker",
        ],
        "of the robot is in no message of '/joint_states'",
    );
}

#[test]
fn no_rest_period_is_refused_with_the_thresholds() {
    fails_with(
        &[
            "extract",
            "fixtures/bags/moving.mcap",
            "--robot",
            UR5,
            "--points",
            "/tracker",
        ],
        "no rest period on '/joint_states': no 0.5 s or longer where every joint's speed stays under 0.005 rad/s",
    );
    fails_with(
        &[
            "extract",
            "fixtures/bags/moving.mcap",
            "--robot",
            UR5,
            "--points",
            "/tracker",
        ],
        "hint: --rest-speed SPEED and --rest-min S set what counts as a rest",
    );
    // Rests shorter than asked for: none.
    fails_with(
        &[
            "extract",
            "fixtures/bags/tiny.mcap",
            "--robot",
            UR5,
            "--points",
            "/tracker",
            "--rest-min",
            "5",
        ],
        "no rest period",
    );
    fails_with(
        &[
            "extract",
            "fixtures/bags/tiny.mcap",
            "--robot",
            UR5,
            "--points",
            "/tracker",
            "--settle",
            "0.6",
        ],
        "the settling time (0.6 s)",
    );
}

#[test]
fn the_output_is_never_an_input() {
    let d = scratch_dir("bags", "over_input");
    let bag = d.join("b.mcap");
    std::fs::copy("fixtures/bags/tiny.mcap", &bag).unwrap();
    let b = bag.to_str().unwrap();
    fails_with(
        &[
            "extract", b, "--robot", UR5, "--points", "/tracker", "--out", b, "--force",
        ],
        "is an input of this command",
    );
    assert_eq!(
        std::fs::read(&bag).unwrap(),
        std::fs::read("fixtures/bags/tiny.mcap").unwrap()
    );
    let out = run(&["extract", b, "--robot", UR5, "--points", "/tracker"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("rests: 3 found"), "{text}");
    assert!(text.contains("scatter mm"), "{text}");
}

#[test]
fn rests_are_matched_to_the_design_and_the_odd_ones_named() {
    let d = scratch_dir("bags", "design");
    // Rests 1 and 3 of the bag, and a pose the run never reached; a `via`
    // row (a move between poses) is not a pose.
    let design = d.join("design.csv");
    let row = |q: &[f64]| q.iter().map(f64::to_string).collect::<Vec<_>>().join(",");
    std::fs::write(
        &design,
        format!(
            "shoulder_pan_joint,shoulder_lift_joint,elbow_joint,wrist_1_joint,wrist_2_joint,wrist_3_joint,id\n{},7\n{},via\n{},9\n{},12\n",
            row(&RESTS[0]),
            row(&RESTS[1]),
            row(&[1.0, -1.0, 1.0, -1.0, -1.0, 1.0]),
            row(&RESTS[2]),
        ),
    )
    .unwrap();
    let out = d.join("m.csv");
    let r = json_of(&[
        "extract",
        "fixtures/bags/tiny.mcap",
        "--robot",
        UR5,
        "--points",
        "/tracker",
        "--design",
        design.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    let rests = r["rests"].as_array().unwrap();
    assert_eq!(rests[0]["design_pose"], 0);
    assert_eq!(rests[2]["design_pose"], 2);
    assert!(rests[1]["design_pose"].is_null());
    let why = rests[1]["left_out"].as_str().unwrap();
    assert!(why.starts_with("reached no pose of the design"), "{why}");
    let missing = r["missing_design_poses"].as_array().unwrap();
    assert_eq!(missing.len(), 1, "{missing:?}");
    assert_eq!(missing[0]["pose"], 1);
    assert_eq!(missing[0]["reason"], "no rest reached it");
    assert_eq!(read_csv(&out).1.len(), 2);
    // The design is an input: never the output.
    fails_with(
        &[
            "extract",
            "fixtures/bags/tiny.mcap",
            "--robot",
            UR5,
            "--points",
            "/tracker",
            "--design",
            design.to_str().unwrap(),
            "--out",
            design.to_str().unwrap(),
            "--force",
        ],
        "is an input of this command",
    );
}

/// `calibrate --bag` reads the bag directly: the same fit as `extract
/// --out` then `calibrate --measurements` of the CSV it wrote (the CSV
/// holds every digit), and the extraction's report beside it.
#[test]
fn calibrate_from_a_bag_is_the_fit_of_the_extracted_csv() {
    let d = scratch_dir("bags", "calibrate");
    let csv = d.join("m.csv");
    let c = csv.to_str().unwrap();
    json_of(&[
        "extract",
        "fixtures/bags/tiny.mcap",
        "--robot",
        UR5,
        "--points",
        "/tracker",
        "--out",
        c,
        "--force",
        "--json",
    ]);
    let fit = |extra: &[&str]| {
        let mut args = vec!["calibrate", "--robot", UR5, "--json"];
        args.extend(extra);
        let out = run(&args);
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(!err.contains("panicked"), "{err}");
        let v: serde_json::Value =
            serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{args:?}: {e}: {err}"));
        (out.status.code(), v)
    };
    let (s_csv, v_csv) = fit(&["--measurements", c]);
    let (s_bag, v_bag) = fit(&["--bag", "fixtures/bags/tiny.mcap", "--points", "/tracker"]);
    assert_eq!(s_csv, s_bag);
    let (p_csv, p_bag) = (
        v_csv["parameters"].as_array().unwrap(),
        v_bag["parameters"].as_array().unwrap(),
    );
    assert_eq!(p_csv.len(), p_bag.len());
    assert!(!p_bag.is_empty());
    for (a, b) in p_csv.iter().zip(p_bag) {
        assert_eq!(a["name"], b["name"]);
        let (x, y) = (
            a["estimate"].as_f64().unwrap(),
            b["estimate"].as_f64().unwrap(),
        );
        assert!((x - y).abs() <= 1e-9 * (1.0 + x.abs()), "{a} vs {b}");
    }
    let rests = v_bag["bag"]["extraction"]["rests"].as_array().unwrap();
    assert_eq!(rests.len(), 3, "{}", v_bag["bag"]);
    assert_eq!(v_bag["poses"], v_csv["poses"]);
}

/// A bag's options are refused without `--bag`, and a file's with it,
/// naming the option; `--joints` is a bag's topic or the images' file.
#[test]
fn a_bags_options_need_a_bag_and_a_files_need_a_file() {
    let base = ["calibrate", "--robot", UR5];
    let with = |extra: &[&'static str]| -> Vec<&'static str> {
        base.iter().chain(extra).copied().collect()
    };
    let bag = ["--bag", "fixtures/bags/tiny.mcap", "--points", "/tracker"];
    for (extra, needle) in [
        (
            &["--measurements", "m.csv", "--rest-speed", "0.01"][..],
            "--bag",
        ),
        (
            &["--measurements", "m.csv", "--time-offset", "0.1"],
            "--bag",
        ),
        (&["--design", "d.json", "--points", "/tracker"], "--bag"),
    ] {
        fails_with(&with(extra), needle);
    }
    let mut args = with(&bag);
    args.extend(["--angle-unit", "deg"]);
    fails_with(
        &args,
        "--angle-unit: not used with --bag --points (a tracker's points from a ROS 2 bag)",
    );
    let mut args = with(&bag);
    args.extend(["--orientation-noise", "0.001"]);
    fails_with(&args, "--orientation-noise: not used with --bag --points");
    let mut args = with(&bag);
    args.extend(["--joints", "/no_such_topic"]);
    fails_with(&args, "/no_such_topic");
    fails_with(
        &with(&["--bag", "fixtures/bags/tiny.mcap"]),
        "give the bag's measurement: --points TOPIC, --poses TOPIC or --tf PARENT:CHILD",
    );
}

/// Each bad bag of the acceptance (cut short in MCAP and SQLite 3, an
/// unknown storage plugin, a topic missing or of another type, a joint of
/// the robot absent from the joint states, no rest) is refused by `extract
/// --out` and by `calibrate --bag --out` with its reason and a non-zero
/// status, and nothing is written: the folder holds the inputs only (no
/// output, no temporary file beside it).
#[test]
fn a_refused_bag_writes_nothing() {
    let d = scratch_dir("bags", "nothing_written");
    let mcap = std::fs::read("fixtures/bags/tiny.mcap").unwrap();
    std::fs::write(d.join("cut.mcap"), &mcap[..mcap.len() / 2]).unwrap();
    let db = std::fs::read("fixtures/bags/tiny_db3/tiny_db3.db3").unwrap();
    std::fs::write(d.join("cut.db3"), &db[..db.len() / 3]).unwrap();
    let plugin = d.join("plugin");
    std::fs::create_dir_all(&plugin).unwrap();
    std::fs::write(
        plugin.join("metadata.yaml"),
        "rosbag2_bagfile_information:\n  version: 9\n  storage_identifier: rosbag_v1\n  relative_file_paths: [a.bag]\n",
    )
    .unwrap();
    let inputs = |d: &Path| {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    let before = inputs(&d);
    let at = |f: &str| d.join(f).to_str().unwrap().to_string();
    let (cut_mcap, cut_db3, plugin) = (at("cut.mcap"), at("cut.db3"), at("plugin"));
    let tiny = "fixtures/bags/tiny.mcap";
    let cases: [(&str, &str, &[&str], &str); 7] = [
        (&cut_mcap, UR5, &["--points", "/tracker"], "cut short"),
        (&cut_db3, UR5, &["--points", "/tracker"], "SQLite 3"),
        (
            &plugin,
            UR5,
            &["--points", "/tracker"],
            "storage plugin 'rosbag_v1' is not read",
        ),
        (tiny, UR5, &["--points", "/nope"], "no topic '/nope'"),
        (
            tiny,
            UR5,
            &["--points", "/camera_info"],
            "is of type sensor_msgs/msg/CameraInfo",
        ),
        (
            tiny,
            "fixtures/stanford.urdf",
            &["--points", "/tracker"],
            "is in no message of '/joint_states'",
        ),
        (
            "fixtures/bags/moving.mcap",
            UR5,
            &["--points", "/tracker"],
            "no rest period",
        ),
    ];
    let (csv, urdf) = (at("m.csv"), at("cal.urdf"));
    for (bag, robot, extra, needle) in cases {
        let mut args = vec!["extract", bag, "--robot", robot];
        args.extend(extra);
        args.extend(["--out", &csv]);
        fails_with(&args, needle);
        let mut args = vec!["calibrate", "--robot", robot, "--bag", bag];
        args.extend(extra);
        args.extend(["--out", &urdf]);
        fails_with(&args, needle);
        assert_eq!(inputs(&d), before, "{bag} {extra:?}: something was written");
    }
}
/// `fixtures/bags/camera.mcap` (`bag_truth.py tiny-images`): the first six
/// committed renders of `fixtures/camera/images/`, one per rest.
const CAMERA_BAG: &str = "fixtures/bags/camera.mcap";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The camera's observations of the bag's `topic`, by the library.
fn bag_observations(topic: &str) -> activecal::io::bag::camera::BagImages {
    use activecal::io::bag::camera::{BagImageSettings, read_bag_images};
    let robot =
        activecal::io::load_robot(&format!("{}#tip=target", root().join(UR5).display())).unwrap();
    let target =
        activecal::io::camera_target::read_target(&root().join("fixtures/camera/board_6x9.yaml"))
            .unwrap();
    let s = BagImageSettings::new("/joint_states", topic, "/camera/camera_info");
    read_bag_images(&root().join(CAMERA_BAG), &robot, &target, &s).unwrap()
}

#[test]
fn a_bags_camera_topics_give_the_pixels_of_the_same_images_read_as_files() {
    use activecal::io::images::{ImageOutcome, joints::read_image_joints, read_images};
    // The same six images as files, with their joints.csv rows.
    let d = scratch_dir("bags", "camera_files");
    let src = root().join("fixtures/camera/images");
    let joints = std::fs::read_to_string(src.join("joints.csv")).unwrap();
    let kept: Vec<&str> = joints.lines().take(7).collect();
    std::fs::write(d.join("joints.csv"), kept.join("\n") + "\n").unwrap();
    for k in 0..6 {
        let f = format!("img_{k:03}.png");
        std::fs::copy(src.join(&f), d.join(&f)).unwrap();
    }
    let robot =
        activecal::io::load_robot(&format!("{}#tip=target", root().join(UR5).display())).unwrap();
    let target =
        activecal::io::camera_target::read_target(&root().join("fixtures/camera/board_6x9.yaml"))
            .unwrap();
    let intrinsics = activecal::io::camera_info::read_camera_info(
        &root().join("fixtures/camera/small_camera_info.yaml"),
    )
    .unwrap();
    let j = read_image_joints(&d.join("joints.csv"), &robot, Default::default()).unwrap();
    let files = read_images(&d, &j, &target, &intrinsics)
        .unwrap()
        .observations;
    // PNG-compressed frames: every rest's image, the same pixels bit for
    // bit (the same bytes decoded), the rest's mean joint values those of
    // joints.csv (the arm stands exactly still: equal to rounding), and
    // the CameraInfo message's camera the YAML's.
    let bag = bag_observations("/camera/image");
    assert_eq!(bag.intrinsics, intrinsics);
    assert_eq!(bag.report.rests.len(), 6, "{:?}", bag.report.rests);
    assert_eq!(bag.observations.pose_ids, files.pose_ids);
    assert_eq!(bag.observations.seen, files.seen);
    for (a, b) in bag.observations.qs.iter().zip(&files.qs) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() < 1e-12, "{a:?} vs {b:?}");
        }
    }
    // A raw mono8 frame on the first rest only: the same pixels; the other
    // rests are listed with the reason.
    let raw = bag_observations("/camera/image_raw");
    assert_eq!(raw.observations.pose_ids, vec![0]);
    assert_eq!(raw.observations.seen[0], files.seen[0]);
    for r in &raw.report.rests[1..] {
        match &r.image.outcome {
            ImageOutcome::LeftOut { reason } => {
                assert!(
                    reason.contains("no image on '/camera/image_raw'"),
                    "{reason}"
                );
            }
            ImageOutcome::Found { .. } => panic!("{:?}", r.image),
        }
    }
}

#[test]
fn extract_writes_a_bags_camera_as_the_observations_csv() {
    let d = scratch_dir("bags", "camera_extract");
    let out = d.join("pixels.csv");
    let r = json_of(&[
        "extract",
        CAMERA_BAG,
        "--robot",
        "fixtures/ur5.urdf#tip=target",
        "--images",
        "/camera/image",
        "--camera-info",
        "/camera/camera_info",
        "--target",
        "fixtures/camera/board_6x9.yaml",
        "--out",
        out.to_str().unwrap(),
        "--force",
        "--json",
    ]);
    assert_eq!(r["rests"].as_array().unwrap().len(), 6, "{r}");
    // The CSV is the observations file the camera route reads: read back,
    // it holds the library's observations (pixels written to 1e-6 px: half
    // a unit of the last digit apart at most).
    let robot =
        activecal::io::load_robot(&format!("{}#tip=target", root().join(UR5).display())).unwrap();
    let target =
        activecal::io::camera_target::read_target(&root().join("fixtures/camera/board_6x9.yaml"))
            .unwrap();
    let bag = bag_observations("/camera/image");
    let back = activecal::io::camera_observations::read_observations(
        &out,
        &robot,
        &target,
        &bag.intrinsics,
        Default::default(),
    )
    .unwrap();
    assert_eq!(back.pose_ids, bag.observations.pose_ids);
    for (a, b) in back
        .seen
        .iter()
        .flatten()
        .zip(bag.observations.seen.iter().flatten())
    {
        match (a, b) {
            (Some(a), Some(b)) => {
                assert!((a[0] - b[0]).abs() <= 5e-7 + 1e-12 && (a[1] - b[1]).abs() <= 5e-7 + 1e-12);
            }
            (None, None) => {}
            _ => panic!("{a:?} vs {b:?}"),
        }
    }
}

#[test]
fn a_bags_camera_without_intrinsics_or_decodable_images_is_refused_by_name() {
    let line = |images: &'static str, info: &'static str| {
        vec![
            "extract",
            CAMERA_BAG,
            "--robot",
            "fixtures/ur5.urdf#tip=target",
            "--images",
            images,
            "--camera-info",
            info,
            "--target",
            "fixtures/camera/board_6x9.yaml",
        ]
    };
    fails_with(
        &line("/camera/image", "/camera/no_info"),
        "no message on '/camera/no_info': the camera's intrinsics are unknown",
    );
    fails_with(
        &line("/camera/image", "/camera/info"),
        "no topic '/camera/info'",
    );
    fails_with(
        &line("/camera/image", "/joint_states"),
        "topic '/joint_states' is of type sensor_msgs/msg/JointState, not sensor_msgs/msg/CameraInfo",
    );
    fails_with(
        &line("/camera/image_yuv", "/camera/camera_info"),
        "rest 1 (image 0): a raw image in encoding 'yuv422'",
    );
    fails_with(
        &line("/camera/image_jpeg", "/camera/no_info"),
        "no message on '/camera/no_info'",
    );
    // The measurement options of points and poses do not go with --images.
    let mut both = line("/camera/image", "/camera/camera_info");
    both.extend(["--points", "/tracker"]);
    fails_with(&both, "--points");
}

/// `/camera/image_jpeg` (`CompressedImage`, format `jpeg`): its first two
/// frames are the bytes of `fixtures/camera/jpeg/img_000.jpg` and
/// `img_001.jpg` and decode to the files' pixels, level for level; the
/// camera's observations of the bag are the files' (the first two rests),
/// and the other rests' 16 × 8 px frames are listed with their size.
#[test]
fn a_bags_jpeg_frames_decode_to_the_pixels_of_their_files() {
    use activecal::io::bag::{Bag, image::decode_message, messages::compressed_image};
    use activecal::io::images::decode::decode_image;
    use activecal::io::images::{ImageOutcome, joints::read_image_joints, read_images};
    let bag = Bag::open(&root().join(CAMERA_BAG)).unwrap();
    let mut frames = Vec::new();
    bag.for_each(&["/camera/image_jpeg"], |m| {
        let msg = compressed_image(m.data).unwrap();
        assert_eq!(msg.encoding, "jpeg");
        frames.push(decode_message(&msg));
        Ok(())
    })
    .unwrap();
    assert_eq!(frames.len(), 6);
    for k in 0..2 {
        let file =
            std::fs::read(root().join(format!("fixtures/camera/jpeg/img_{k:03}.jpg"))).unwrap();
        let want = decode_image(&file).unwrap();
        assert_eq!((want.width, want.height), (320, 240));
        assert_eq!(frames[k].as_ref().unwrap(), &want, "frame {k}");
    }
    let robot =
        activecal::io::load_robot(&format!("{}#tip=target", root().join(UR5).display())).unwrap();
    let target =
        activecal::io::camera_target::read_target(&root().join("fixtures/camera/board_6x9.yaml"))
            .unwrap();
    let intrinsics = activecal::io::camera_info::read_camera_info(
        &root().join("fixtures/camera/small_camera_info.yaml"),
    )
    .unwrap();
    let dir = root().join("fixtures/camera/jpeg");
    let j = read_image_joints(&dir.join("joints.csv"), &robot, Default::default()).unwrap();
    let files = read_images(&dir, &j, &target, &intrinsics)
        .unwrap()
        .observations;
    let from_bag = bag_observations("/camera/image_jpeg");
    assert_eq!(from_bag.observations.pose_ids, vec![0, 1]);
    assert_eq!(from_bag.observations.seen, files.seen);
    for r in &from_bag.report.rests[2..] {
        match &r.image.outcome {
            ImageOutcome::LeftOut { reason } => {
                assert!(reason.contains("16 × 8 px"), "{reason}");
            }
            ImageOutcome::Found { .. } => panic!("{:?}", r.image),
        }
    }
}
