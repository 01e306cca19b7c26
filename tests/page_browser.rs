//! The 3D page of report folders (`index.html`) in a real browser: headless
//! Chromium (Debian's, installed by `scripts/setup`) opens it from
//! `file://`, one launch per check. Skipped only when Chromium is missing
//! and `ACTIVECAL_REQUIRE_BROWSER` is unset (`scripts/test` sets it).
//!
//! What is checked: no console message and no uncaught exception (the
//! page logs nothing when it works; Chromium's own WebGL driver notes
//! aside); the page's read-out (`<pre id="readout">`) counts the design's
//! poses, the URDF's links and the meshes' triangles; the pose shown after
//! `#pose=k` or a click on the k-th list entry is k; the link frames the
//! page places (three.js's world matrices, read back) equal the URDF's own
//! forward kinematics ([`common::urdf_fk`], independent of activecal's
//! importer) to 1e-9 m and 1e-9 per rotation entry — the issue's
//! tolerance: the page's matrices are activecal's f64 numbers passed
//! through JSON (exact) and a product with the identity (exact), so only
//! the two kinematics' rounding, ~1e-15, separates them, while a wrong
//! frame or joint is off by millimetres; and screenshots: the canvas is
//! not blank, and the first and last poses differ where the robot moved.

use crate::common::{run, scratch_dir, urdf_fk};
use serde_json::Value;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

const CHROMIUM: &str = "/usr/bin/chromium";

/// The browser, or `None` (the test is skipped) when it is missing and not
/// required.
fn chromium() -> Option<&'static str> {
    if Path::new(CHROMIUM).is_file() {
        return Some(CHROMIUM);
    }
    assert!(
        std::env::var_os("ACTIVECAL_REQUIRE_BROWSER").is_none(),
        "ACTIVECAL_REQUIRE_BROWSER is set but {CHROMIUM} is missing: run scripts/setup"
    );
    eprintln!("skipped: {CHROMIUM} missing (scripts/setup installs it)");
    None
}

/// Runs Chromium headless on `page` with URL hash `hash` and `extra`
/// arguments; returns (stdout, the page's console lines).
fn browse(page: &Path, hash: &str, extra: &[&str]) -> (String, Vec<String>) {
    let profile = page.with_file_name(format!("profile-{}", hash.replace(['#', '='], "")));
    let url = format!("file://{}#{hash}", page.display());
    let out = Command::new("timeout")
        .arg("120")
        .arg(chromium().expect("checked by the caller"))
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--window-size=1280,800",
            "--enable-logging=stderr",
            "--v=0",
            "--virtual-time-budget=5000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(&url)
        .output()
        .expect("chromium runs");
    assert!(out.status.success(), "chromium on {url}: {:?}", out.status);
    let console = String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| l.contains(":CONSOLE") && !l.contains("GL Driver Message"))
        .map(str::to_string)
        .collect();
    (String::from_utf8_lossy(&out.stdout).into_owned(), console)
}

/// The page's read-out after it opened at `hash`, asserting a clean console.
fn readout(page: &Path, hash: &str) -> Value {
    let (dom, console) = browse(page, hash, &["--dump-dom"]);
    assert!(
        console.is_empty(),
        "{}: console: {console:#?}",
        page.display()
    );
    let start = dom
        .find("<pre id=\"readout\"")
        .expect("the read-out element");
    let text = &dom[start..];
    let text = &text[text.find('>').unwrap() + 1..text.find("</pre>").unwrap()];
    let text = text
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&");
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("read-out '{text}': {e}"))
}

/// A screenshot's pixels as RGB triples, and its width.
fn screenshot(page: &Path, hash: &str) -> (Vec<[u8; 3]>, usize) {
    let shot = page.with_file_name(format!("shot-{}.png", hash.replace(['#', '='], "")));
    let arg = format!("--screenshot={}", shot.display());
    let (_, console) = browse(page, hash, &[&arg]);
    assert!(console.is_empty(), "console: {console:#?}");
    let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&shot).unwrap()));
    let mut r = dec.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size()];
    let info = r.next_frame(&mut buf).unwrap();
    let step = match info.color_type {
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        other => panic!("{}: colour type {other:?}", shot.display()),
    };
    buf.truncate(info.buffer_size());
    let px = buf.chunks_exact(step).map(|p| [p[0], p[1], p[2]]).collect();
    (px, info.width as usize)
}

/// `select --report` for a robot; returns the report folder and its JSON.
fn select(name: &str, robot: &[&str], extra: &[&str]) -> (PathBuf, Value) {
    let dir = scratch_dir("page", name);
    let report = dir.join("report");
    let mut args = vec!["select"];
    args.extend(robot);
    args.extend([
        "--pool", "sobol", "--count", "128", "--n", "12", "--order", "time", "--json", "--report",
    ]);
    let r = report.display().to_string();
    args.push(&r);
    args.extend(extra);
    let out = run(&args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    (report, v)
}

/// The venv's example-robot-data, when installed (the UR5's and Panda's
/// visual meshes): `--package-dir` arguments.
fn erd_packages() -> Vec<String> {
    let share = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(".venv/lib/python3.11/site-packages/cmeel.prefix/share");
    if share.is_dir() {
        vec!["--package-dir".into(), share.display().to_string()]
    } else {
        Vec::new()
    }
}

/// Whether link `l` is `base` or below it.
fn below<'a>(parent: &HashMap<&str, &'a str>, base: &str, mut l: &'a str) -> bool {
    loop {
        if l == base {
            return true;
        }
        match parent.get(l) {
            Some(p) => l = p,
            None => return false,
        }
    }
}

/// Checks every link below `base` that the page placed at pose `k` against
/// the URDF's own kinematics; returns how many were compared.
fn frames_match(urdf: &str, base: &str, v: &Value, ro: &Value, k: usize) -> usize {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(urdf)).unwrap();
    let u = urdf_rs::read_from_string(&text).unwrap();
    let names: Vec<String> = serde_json::from_value(v["selection"]["joint_names"].clone())
        .or_else(|_| serde_json::from_value(v["joint_names"].clone()))
        .unwrap();
    let q: Vec<f64> = serde_json::from_value(v["configurations"][k]["q"].clone()).unwrap();
    let mut values: HashMap<String, f64> = u.joints.iter().map(|j| (j.name.clone(), 0.0)).collect();
    for (n, x) in names.iter().zip(&q) {
        values.insert(n.clone(), *x);
    }
    let parent: HashMap<&str, &str> = u
        .joints
        .iter()
        .map(|j| (j.child.link.as_str(), j.parent.link.as_str()))
        .collect();
    let links: Vec<String> = ro["link_names"].as_array().map_or_else(Vec::new, |a| {
        a.iter().map(|x| x.as_str().unwrap().to_string()).collect()
    });
    let mut compared = 0;
    for (i, name) in links.iter().enumerate() {
        if !below(&parent, base, name) {
            continue;
        }
        let want = urdf_fk(&u, base, name, &values).to_homogeneous();
        let got: Vec<f64> = serde_json::from_value(ro["world"][i].clone()).unwrap();
        for (c, (g, w)) in got.iter().zip(want.as_slice()).enumerate() {
            assert!(
                (g - w).abs() <= 1e-9,
                "{urdf} pose {k} link {name} entry {c}: page {g}, URDF {w}"
            );
        }
        compared += 1;
    }
    compared
}

#[test]
fn ur5_page_places_its_links_as_the_urdf_and_moves_between_poses() {
    if chromium().is_none() {
        return;
    }
    let urdf = "fixtures/example-robot-data/ur5_robot.urdf";
    let pk = erd_packages();
    let mut extra: Vec<&str> = pk.iter().map(String::as_str).collect();
    extra.extend([
        "--floor",
        "-0.3",
        "--obstacle",
        "box:0.6,0.4,0.1,0.2,0.2,0.6",
    ]);
    let (dir, v) = select("ur5", &["--robot", urdf, "--tip", "tool0"], &extra);
    let page = dir.join("index.html");
    let size = std::fs::metadata(&page).unwrap().len();
    assert!(
        size < 10_000_000,
        "the UR5 page is {size} bytes, over 10 MB"
    );
    let sel = &v;
    let n = sel["configurations"].as_array().unwrap().len();
    let last = n - 1;
    let ro = readout(&page, &format!("pose={last}"));
    assert_eq!(ro["poses"], n);
    assert_eq!(ro["shown"], last);
    assert_eq!(ro["links"], ro["link_names"].as_array().unwrap().len());
    if !pk.is_empty() {
        // ur5_robot.urdf: seven visual meshes, 95 672 triangles as welded.
        assert_eq!(ro["meshes"], 7);
        assert!(
            ro["triangles"].as_u64().unwrap() > 10_000,
            "{}",
            ro["triangles"]
        );
    }
    let compared = frames_match(urdf, "base_link", sel, &ro, last);
    assert!(compared >= 8, "{compared} links compared");
    // The least clearance of the pose shown (the pool's collision filter):
    // a pose the filter kept is free, and the page draws red exactly the
    // links of its closest pair.
    let c = &ro["clearance"];
    let d = c["distance"]
        .as_f64()
        .expect("a clearance with a collision filter");
    assert!(d > 0.0 && d < 2.0, "clearance {d} m");
    assert!(!c["links"].as_array().unwrap().is_empty(), "{c}");
    assert_eq!(ro["red"], c["links"], "the links drawn red");
    // The page alone, away from the report's other files, is the same page.
    let alone = scratch_dir("page", "ur5-alone").join("index.html");
    std::fs::copy(&page, &alone).unwrap();
    assert_eq!(
        readout(&alone, &format!("pose={last}"))["world"],
        ro["world"]
    );
    // A click on the list's third entry shows pose 2.
    let clicked = readout(&page, "click=2");
    assert_eq!(clicked["shown"], 2);
    assert_eq!(frames_match(urdf, "base_link", sel, &clicked, 2), compared);
    // Screenshots: something drawn in the canvas, and the robot moved.
    let (first, w) = screenshot(&page, "pose=0");
    let (end, _) = screenshot(&page, &format!("pose={last}"));
    let c: Vec<usize> = ["0", "1", "2", "3"]
        .iter()
        .map(|i| ro["canvas"][i.parse::<usize>().unwrap()].as_f64().unwrap() as usize)
        .collect();
    let inside = |i: usize| {
        let (x, y) = (i % w, i / w);
        x > c[0] && x < c[0] + c[2] && y > c[1] && y < c[1] + c[3]
    };
    let drawn = (0..first.len())
        .filter(|&i| inside(i) && first[i].iter().any(|&p| p < 200))
        .count();
    let area = c[2] * c[3];
    assert!(
        drawn * 100 > area,
        "{drawn} dark pixels in a canvas of {area}"
    );
    let moved = (0..first.len())
        .filter(|&i| inside(i) && first[i] != end[i])
        .count();
    assert!(
        moved > 500,
        "{moved} pixels differ between the first and last pose"
    );
}

/// The URDF's root link (the link no joint has as its child).
fn root_of(urdf: &str) -> String {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(urdf)).unwrap();
    let u = urdf_rs::read_from_string(&text).unwrap();
    let children: Vec<&str> = u.joints.iter().map(|j| j.child.link.as_str()).collect();
    u.links
        .iter()
        .find(|l| !children.contains(&l.name.as_str()))
        .unwrap()
        .name
        .clone()
}

#[test]
fn panda_and_tiago_pages_place_every_link_as_their_urdfs() {
    if chromium().is_none() {
        return;
    }
    for (name, urdf, tip, at_least) in [
        (
            "panda",
            "fixtures/example-robot-data/panda.urdf",
            "panda_hand_tcp",
            10,
        ),
        ("tiago", "fixtures/figaroh/tiago.urdf", "arm_tool_link", 30),
    ] {
        let (dir, v) = select(name, &["--robot", urdf, "--tip", tip], &[]);
        let n = v["configurations"].as_array().unwrap().len();
        let ro = readout(&dir.join("index.html"), &format!("pose={}", n - 1));
        assert_eq!(ro["poses"], n, "{name}");
        assert_eq!(ro["shown"], n - 1, "{name}");
        let compared = frames_match(urdf, &root_of(urdf), &v, &ro, n - 1);
        assert!(compared >= at_least, "{name}: {compared} links compared");
    }
}

#[test]
fn calibration_page_shows_every_pose_and_marks_the_flagged_ones() {
    if chromium().is_none() {
        return;
    }
    let dir = scratch_dir("page", "calibrate").join("report");
    let r = dir.display().to_string();
    let out = run(&[
        "calibrate",
        "--robot",
        "fixtures/example-robot-data/ur5_robot.urdf",
        "--frames",
        "fixtures/truth/ur5/nominal.yaml",
        "--measurements",
        "fixtures/truth/ur5/meas0.csv",
        "--report",
        &r,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rep: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    let flagged = rep["outliers"]["left_out"].as_array().map_or(0, Vec::len);
    let page = dir.join("index.html");
    let (dom, console) = browse(&page, "pose=0", &["--dump-dom"]);
    assert!(console.is_empty(), "console: {console:#?}");
    assert_eq!(
        dom.matches("<li class=\"flagged\"").count(),
        flagged,
        "flagged poses listed"
    );
    let ro = readout(&page, "pose=29");
    assert_eq!(ro["poses"], 30);
    assert_eq!(ro["shown"], 29);
    // The residual the page draws (fitted point → measured point) is the
    // one the gross-error test reported for each pose it left out: the
    // page's points are the fit's, not another model's. The report rounds
    // nothing here (f64 through JSON): 1e-9 mm is rounding of the two
    // frame changes.
    let html = std::fs::read_to_string(&page).unwrap();
    let data = &html[html.find("id=\"page-data\">").unwrap() + 15..];
    let data: Value = serde_json::from_str(&data[..data.find("</script>").unwrap()]).unwrap();
    for o in rep["outliers"]["left_out"].as_array().into_iter().flatten() {
        let k = o["pose"].as_u64().unwrap() as usize;
        let p = &data["poses"][k];
        assert_eq!(p["mark"], "flagged");
        let d: f64 = (0..3)
            .map(|i| {
                (p["measured"][i].as_f64().unwrap() - p["fitted"][i].as_f64().unwrap()).powi(2)
            })
            .sum::<f64>()
            .sqrt();
        let want = o["residual_mm"].as_f64().unwrap();
        assert!(
            (d * 1e3 - want).abs() < 1e-9,
            "pose {k}: page {} mm, fit {want} mm",
            d * 1e3
        );
    }
}

#[test]
fn a_report_folder_written_twice_holds_the_same_page() {
    let pages: Vec<Vec<u8>> = ["a", "b"]
        .iter()
        .map(|n| {
            let (dir, _) = select(
                &format!("twice-{n}"),
                &[
                    "--robot",
                    "fixtures/example-robot-data/ur5_robot.urdf",
                    "--tip",
                    "tool0",
                ],
                &[],
            );
            std::fs::read(dir.join("index.html")).unwrap()
        })
        .collect();
    assert!(pages[0].len() > 100_000, "{} bytes", pages[0].len());
    assert!(pages[0] == pages[1], "the two pages differ");
}

#[test]
fn tiago_head_camera_page_shows_the_frustum_at_every_pose() {
    if chromium().is_none() {
        return;
    }
    let dir = scratch_dir("page", "camera").join("report");
    let r = dir.display().to_string();
    let out = run(&[
        "select",
        "--robot",
        "fixtures/figaroh/tiago.urdf#tip=arm_tool_link",
        "--camera-link",
        "head_2_link",
        "--camera-info",
        "fixtures/camera/tiago_xtion.yaml",
        "--target",
        "fixtures/camera/tiago_board.yaml",
        "--camera-pose=0.0908,0.0800,-0.0220,-3.1416,-1.5708,0.0000",
        "--target-pose=0.0800,-0.0400,0.0600,0.0000,1.5708,0.0000",
        "--image-margin",
        "20",
        "--distance",
        "0.25,1.5",
        "--n",
        "30",
        "--count",
        "3000",
        "--report",
        &r,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let page = dir.join("index.html");
    let html = std::fs::read_to_string(&page).unwrap();
    let data = &html[html.find("id=\"page-data\">").unwrap() + 15..];
    let data: Value = serde_json::from_str(&data[..data.find("</script>").unwrap()]).unwrap();
    let cam = &data["sensor"];
    assert_eq!(cam["kind"], "camera");
    assert_eq!(cam["placements"].as_array().unwrap().len(), 30);
    assert_eq!(cam["boards"][0].as_array().unwrap().len(), 4);
    let ro = readout(&page, "pose=29");
    assert_eq!(ro["poses"], 30);
    assert_eq!(ro["shown"], 29);
    // The camera rides on the head: its placement differs between poses
    // exactly when the head link moved.
    let head = ro["link_names"]
        .as_array()
        .unwrap()
        .iter()
        .position(|n| n == "head_2_link")
        .unwrap();
    let first: Value = serde_json::from_value(data["poses"][0]["links"][head].clone()).unwrap();
    let last: Value = serde_json::from_value(data["poses"][29]["links"][head].clone()).unwrap();
    assert_eq!(
        first == last,
        cam["placements"][0] == cam["placements"][29],
        "the camera moves with the head"
    );
}

/// The Panda eye-to-hand camera design with a line of sight (its own links
/// hide the board from some configurations): at the first and last pose,
/// the page draws one ray per board point inside the image, and the clear
/// ones are the points `select` says the pose sees (`points_seen`, counted
/// by the same check when the design was chosen); the rays leave from the
/// camera the page draws.
#[test]
fn camera_page_draws_the_lines_of_sight_the_design_counted() {
    if chromium().is_none() {
        return;
    }
    let dir = scratch_dir("page", "sight").join("report");
    let r = dir.display().to_string();
    let out = run(&[
        "select",
        "--robot",
        "fixtures/example-robot-data/panda.urdf#tip=panda_hand_tcp",
        "--camera-info",
        "fixtures/camera/camera_info.yaml",
        "--target",
        "fixtures/camera/board.yaml",
        "--mounting",
        "eye-to-hand",
        "--camera-pose=1.2,0.6,0.9,-2.0985,0.0,2.0779",
        "--target-pose=-0.0853,0.0568,0.02,3.141592653589793,0.0,0.03",
        "--image-margin",
        "20",
        "--distance",
        "0.3,2.0",
        "--n",
        "14",
        "--count",
        "1500",
        "--line-of-sight",
        "--json",
        "--report",
        &r,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let page = dir.join("index.html");
    let html = std::fs::read_to_string(&page).unwrap();
    let data = &html[html.find("id=\"page-data\">").unwrap() + 15..];
    let data: Value = serde_json::from_str(&data[..data.find("</script>").unwrap()]).unwrap();
    let cam = &data["sensor"];
    assert_eq!(cam["rays"].as_array().unwrap().len(), 14);
    for k in [0, 13] {
        let ro = readout(&page, &format!("pose={k}"));
        assert_eq!(ro["shown"], k);
        let rays = cam["rays"][k].as_array().unwrap();
        let m = &ro["marks"];
        assert_eq!(m["rays_clear"], v["points_seen"][k], "pose {k}");
        assert_eq!(
            m["rays_clear"].as_u64().unwrap() + m["rays_blocked"].as_u64().unwrap(),
            rays.len() as u64,
            "pose {k}"
        );
        for ray in rays {
            for i in 0..3 {
                let eye = cam["placements"][k][12 + i].as_f64().unwrap();
                assert!((ray["from"][i].as_f64().unwrap() - eye).abs() < 1e-9);
            }
        }
    }
}

/// A contact calibration's page (MUKCa's Panda, `calibrate --report`)
/// draws one sphere per socket the fit reports, and no plane (the file has
/// none).
#[test]
fn contact_page_draws_every_socket() {
    if chromium().is_none() {
        return;
    }
    let dir = scratch_dir("page", "contacts").join("report");
    let r = dir.display().to_string();
    let mut args = vec![
        "calibrate",
        "--robot",
        "fixtures/mukca/panda.urdf",
        "--tip",
        "ball_link",
        "--measurements",
        "fixtures/mukca/panda_2.csv",
        "--json",
        "--report",
        &r,
    ];
    let blocks = [
        "back_left",
        "back_right",
        "front_center",
        "front_left",
        "front_right",
        "high",
        "mid-high",
        "mid_left",
        "mid_right",
    ];
    let distances: Vec<String> = blocks
        .iter()
        .map(|b| format!("--point-distance={b}/0,{b}/1=0.05"))
        .collect();
    args.extend(distances.iter().map(String::as_str));
    let out = run(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let points = v["fit"]["points"].as_array().unwrap().len();
    assert!(points >= 2);
    let ro = readout(&dir.join("index.html"), "pose=0");
    assert_eq!(ro["marks"]["sockets"], points);
    assert_eq!(ro["marks"]["planes"], 0);
    // A pose per row fitted: the file's less those left out as gross errors.
    let left_out = v["outliers"]["left_out"].as_array().unwrap().len() as u64;
    assert_eq!(
        ro["poses"].as_u64().unwrap(),
        v["rows"].as_u64().unwrap() - left_out
    );
}
