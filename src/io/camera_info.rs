//! A camera's intrinsics from the two files calibration tools write:
//!
//! * ROS's `camera_info` YAML (`camera_calibration`, `camera_info_manager`):
//!   `image_width`, `image_height`, `camera_matrix: {rows: 3, cols: 3,
//!   data: [fx, 0, cx, 0, fy, cy, 0, 0, 1]}`, `distortion_model:
//!   plumb_bob`, `distortion_coefficients: {rows: 1, cols: 5, data: [k1,
//!   k2, p1, p2, k3]}`, or `distortion_model: equidistant` with 4
//!   coefficients `[k1, k2, k3, k4]` (the fisheye model,
//!   [`crate::measure::fisheye`]; the rectification and projection
//!   matrices are not read);
//! * OpenCV's `FileStorage` YAML (`%YAML:1.0` on the first line, matrices
//!   tagged `!!opencv-matrix` with `rows`, `cols`, `dt`, `data`; the
//!   calibration sample's keys `camera_matrix` / `cameraMatrix` and
//!   `distortion_coefficients` / `distCoeffs`). A fisheye file is
//!   recognised by `fisheye_model: 1`, the key OpenCV's calibration
//!   tutorial (`camera_calibration.cpp`) writes (or by a ROS-style
//!   `distortion_model: equidistant`); without either, its coefficients are
//!   plumb_bob's (4 of them are `k1, k2, p1, p2` with k3 = 0, as
//!   `cv::calibrateCamera` reads them), so an unmarked fisheye file is read
//!   wrongly: mark it.
//!
//! Checked: the image size (both > 0 pixels), a 3 × 3 camera matrix with
//! its zeros and 1 where a pinhole has them, positive focal lengths, a
//! principal point inside the image, the distortion model named (ROS: a
//! file without `distortion_model` is refused with the line of its
//! coefficients and the accepted values, never taken as plumb_bob),
//! known and supported (plumb_bob: 5 coefficients, or 4 with k3 = 0;
//! OpenCV's 8, 12 or 14 only when the coefficients past the fifth are
//! zero; equidistant: exactly 4). Every error names the file, the key and
//! its line and column.

use crate::error::{Error, Result};
use crate::measure::pinhole::{Distortion, Intrinsics};
use serde::Deserialize;
use serde_saphyr::Spanned;
use std::path::Path;

#[derive(Deserialize)]
struct MatrixEntry {
    rows: Option<Spanned<i64>>,
    cols: Option<Spanned<i64>>,
    data: Option<Spanned<Vec<f64>>>,
}

#[derive(Deserialize)]
struct InfoEntry {
    image_width: Option<Spanned<i64>>,
    image_height: Option<Spanned<i64>>,
    #[serde(alias = "cameraMatrix")]
    camera_matrix: Option<Spanned<MatrixEntry>>,
    distortion_model: Option<Spanned<String>>,
    #[serde(alias = "distCoeffs", alias = "dist_coeffs")]
    distortion_coefficients: Option<Spanned<MatrixEntry>>,
    /// OpenCV's calibration tutorial's fisheye flag (0 or 1).
    fisheye_model: Option<Spanned<i64>>,
}

/// Whether `text` is an OpenCV `FileStorage` YAML (its `%YAML:` directive
/// or a `!!opencv-matrix` tag), whose distortion model may go unnamed.
fn is_opencv(text: &str) -> bool {
    text.starts_with("%YAML:") || text.contains("!!opencv-matrix")
}

/// Reads a camera's intrinsics from a ROS `camera_info` or OpenCV YAML
/// file (see the module documentation).
pub fn read_camera_info(path: &Path) -> Result<Intrinsics> {
    let text = super::read::read_text(path)?;
    parse_camera_info(&text, &path.display().to_string())
}

/// The text with OpenCV's YAML 1.0 directive and matrix tags blanked, every
/// other character (and so every line and column) kept.
fn plain_yaml(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for (i, line) in text.split_inclusive('\n').enumerate() {
        if i == 0 && line.starts_with("%YAML:") {
            out.push('#');
            out.push_str(&line[1..]);
        } else {
            out.push_str(&line.replace("!!opencv-matrix", "               "));
        }
    }
    out
}

/// Parses intrinsics from `text` (from `origin`, for messages).
pub fn parse_camera_info(text: &str, origin: &str) -> Result<Intrinsics> {
    let err = |message: String| Error::Parse {
        path: origin.to_string(),
        message,
    };
    let f: InfoEntry = serde_saphyr::from_str(&plain_yaml(text)).map_err(|e| {
        let at = e
            .location()
            .map(|l| format!("line {}, column {}: ", l.line(), l.column()))
            .unwrap_or_default();
        err(format!(
            "{at}not a camera_info or OpenCV calibration YAML: {}",
            e.without_snippet()
        ))
    })?;
    build(&f, is_opencv(text)).map_err(err)
}

fn at<T>(s: &Spanned<T>) -> String {
    format!(
        "line {}, column {}",
        s.referenced.line(),
        s.referenced.column()
    )
}

fn size(key: &str, v: Option<&Spanned<i64>>) -> std::result::Result<u32, String> {
    let v = v.ok_or_else(|| {
        format!("no '{key}': the image size (pixels) is needed to tell which pixels are inside")
    })?;
    u32::try_from(v.value)
        .ok()
        .filter(|&n| n > 0)
        .ok_or_else(|| {
            format!(
                "{} ('{key}'): {} is not a positive number of pixels",
                at(v),
                v.value
            )
        })
}

/// A matrix's data, its shape checked against `shapes` (rows, cols) when
/// the file gives one.
fn data(
    key: &str,
    m: &Spanned<MatrixEntry>,
    shapes: &[(i64, i64)],
) -> std::result::Result<Vec<f64>, String> {
    let d = m
        .value
        .data
        .as_ref()
        .ok_or_else(|| format!("{} ('{key}'): no 'data'", at(m)))?;
    if let (Some(r), Some(c)) = (&m.value.rows, &m.value.cols) {
        let ok = shapes
            .iter()
            .any(|&(sr, sc)| sr == r.value && sc == c.value)
            && (r.value * c.value) as usize == d.value.len();
        if !ok {
            let want: Vec<String> = shapes.iter().map(|(r, c)| format!("{r}×{c}")).collect();
            return Err(format!(
                "{} ('{key}'): a {}×{} matrix with {} numbers; expected {} with rows × cols numbers",
                at(m),
                r.value,
                c.value,
                d.value.len(),
                want.join(" or ")
            ));
        }
    }
    if let Some(k) = d.value.iter().position(|v| !v.is_finite()) {
        return Err(format!(
            "{} ('{key}.data'): entry {} is not a finite number",
            at(d),
            k + 1
        ));
    }
    Ok(d.value.clone())
}

fn build(f: &InfoEntry, opencv: bool) -> std::result::Result<Intrinsics, String> {
    let width = size("image_width", f.image_width.as_ref())?;
    let height = size("image_height", f.image_height.as_ref())?;
    let km = f
        .camera_matrix
        .as_ref()
        .ok_or("no 'camera_matrix': the 3×3 matrix [fx 0 cx; 0 fy cy; 0 0 1] (pixels) is needed")?;
    let k = data("camera_matrix", km, &[(3, 3)])?;
    if k.len() != 9 {
        return Err(format!(
            "{} ('camera_matrix'): {} numbers; a 3×3 matrix has 9",
            at(km),
            k.len()
        ));
    }
    let pinhole = k[1].abs() <= 1e-9 * k[0].abs()
        && k[3] == 0.0
        && k[6] == 0.0
        && k[7] == 0.0
        && (k[8] - 1.0).abs() < 1e-12;
    if !pinhole {
        return Err(format!(
            "{} ('camera_matrix'): [{}] is not a pinhole camera matrix [fx 0 cx; 0 fy cy; 0 0 1] (no skew)",
            at(km),
            k.iter().map(f64::to_string).collect::<Vec<_>>().join(", ")
        ));
    }
    let distortion = distortion(f, opencv)?;
    let c = Intrinsics {
        width,
        height,
        fx: k[0],
        fy: k[4],
        cx: k[2],
        cy: k[5],
        distortion,
    };
    c.check()
        .map_err(|e| format!("{} ('camera_matrix'): {e}", at(km)))?;
    Ok(c)
}

/// The distortion model a file names: ROS's `distortion_model` or
/// OpenCV's `fisheye_model` flag. Neither is an error in a ROS file (the
/// same coefficients mean another camera under each model, and a fisheye
/// read as plumb_bob fits tens of pixels off); an OpenCV file (`opencv`)
/// without either is plumb_bob, as `cv::calibrateCamera` reads it.
fn model(f: &InfoEntry, opencv: bool) -> std::result::Result<&'static str, String> {
    let flag = match &f.fisheye_model {
        None => None,
        Some(v) if v.value == 0 || v.value == 1 => Some(v.value == 1),
        Some(v) => {
            return Err(format!(
                "{} ('fisheye_model'): {}; OpenCV writes 0 (plumb_bob) or 1 (equidistant fisheye)",
                at(v),
                v.value
            ));
        }
    };
    let named = match &f.distortion_model {
        None => None,
        Some(m) => match m.value.as_str() {
            "plumb_bob" => Some("plumb_bob"),
            "equidistant" => Some("equidistant"),
            other => {
                return Err(format!(
                    "{} ('distortion_model'): '{other}' is not supported; this camera model reads plumb_bob (k1, k2, p1, p2, k3) and equidistant (the fisheye model: k1, k2, k3, k4)",
                    at(m)
                ));
            }
        },
    };
    match (named, flag) {
        (Some(n), Some(fish)) if (n == "equidistant") != fish => Err(format!(
            "{} ('fisheye_model'): {} contradicts distortion_model '{n}'",
            f.fisheye_model.as_ref().map(at).unwrap_or_default(),
            u8::from(fish)
        )),
        (Some(n), _) => Ok(n),
        (None, Some(true)) => Ok("equidistant"),
        (None, Some(false)) => Ok("plumb_bob"),
        (None, None) if opencv => Ok("plumb_bob"),
        (None, None) => Err(format!(
            "{}no 'distortion_model': name the model of the coefficients, 'distortion_model: plumb_bob' (k1, k2, p1, p2, k3) or 'distortion_model: equidistant' (the fisheye model: k1, k2, k3, k4)",
            f.distortion_coefficients
                .as_ref()
                .map(|d| format!("{} ('distortion_coefficients'): ", at(d)))
                .unwrap_or_default()
        )),
    }
}

/// The distortion model and its coefficients.
fn distortion(f: &InfoEntry, opencv: bool) -> std::result::Result<Distortion, String> {
    let model = model(f, opencv)?;
    let Some(dm) = &f.distortion_coefficients else {
        return Err(format!(
            "no 'distortion_coefficients': give them ({}; all 0 for an undistorted image)",
            if model == "plumb_bob" {
                "k1, k2, p1, p2, k3"
            } else {
                "k1, k2, k3, k4"
            }
        ));
    };
    // A row or a column of coefficients; the count a model takes is
    // checked after.
    let shapes: Vec<(i64, i64)> = (1..=14).flat_map(|n| [(1, n), (n, 1)]).collect();
    let d = data("distortion_coefficients", dm, &shapes)?;
    if model == "equidistant" {
        return match d[..] {
            [k1, k2, k3, k4] => Ok(Distortion::Equidistant([k1, k2, k3, k4])),
            _ => Err(format!(
                "{} ('distortion_coefficients'): {} coefficients; equidistant (fisheye) has 4 (k1, k2, k3, k4)",
                at(dm),
                d.len()
            )),
        };
    }
    if !matches!(d.len(), 4 | 5 | 8 | 12 | 14) {
        return Err(format!(
            "{} ('distortion_coefficients'): {} coefficients; plumb_bob has 5 (k1, k2, p1, p2, k3)",
            at(dm),
            d.len()
        ));
    }
    if let Some(k) = d.iter().skip(5).position(|v| *v != 0.0) {
        return Err(format!(
            "{} ('distortion_coefficients'): coefficient {} is {}: the rational and thin-prism models (k4…) are not supported, only plumb_bob (k1, k2, p1, p2, k3)",
            at(dm),
            k + 6,
            d[k + 5]
        ));
    }
    Ok(Distortion::PlumbBob([
        d[0],
        d[1],
        d[2],
        d[3],
        d.get(4).copied().unwrap_or(0.0),
    ]))
}

/// A ROS `camera_info` YAML of `intrinsics` (as `camera_calibration`
/// writes it: image size, `camera_name`, the camera matrix, the distortion
/// model, `plumb_bob` or `equidistant`, with its 5 or 4 coefficients, an
/// identity rectification and the projection matrix `[K |
/// 0]`), every number in Rust's shortest form that reads back to the same
/// value; `comment` goes first, on `#` lines.
#[must_use]
pub fn render_camera_info(intrinsics: &Intrinsics, camera_name: &str, comment: &str) -> String {
    let i = intrinsics;
    let f = |v: f64| format!("{v:?}");
    let list = |v: &[f64]| v.iter().map(|x| f(*x)).collect::<Vec<_>>().join(", ");
    let mut s = String::new();
    for line in comment.lines() {
        s += &format!("# {line}\n");
    }
    s += &format!(
        "image_width: {}\nimage_height: {}\ncamera_name: {camera_name}\n",
        i.width, i.height
    );
    s += &format!(
        "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [{}]\n",
        list(&[i.fx, 0.0, i.cx, 0.0, i.fy, i.cy, 0.0, 0.0, 1.0])
    );
    let d = i.distortion.coefficients();
    s += &format!("distortion_model: {}\n", i.distortion.model());
    s += &format!(
        "distortion_coefficients:\n  rows: 1\n  cols: {}\n  data: [{}]\n",
        d.len(),
        list(d)
    );
    s += "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n";
    s += &format!(
        "projection_matrix:\n  rows: 3\n  cols: 4\n  data: [{}]\n",
        list(&[
            i.fx, 0.0, i.cx, 0.0, 0.0, i.fy, i.cy, 0.0, 0.0, 0.0, 1.0, 0.0
        ])
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    const ROS: &str = "image_width: 1280
image_height: 960
camera_name: wrist
camera_matrix:
  rows: 3
  cols: 3
  data: [900.0, 0.0, 640.5, 0.0, 905.0, 480.2, 0.0, 0.0, 1.0]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.1, 0.05, 0.001, -0.0005, -0.01]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
";

    const OPENCV: &str = "%YAML:1.0
---
image_width: 640
image_height: 480
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 500., 0., 320., 0., 501., 240., 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 5
   cols: 1
   dt: d
   data: [ 0.1, -0.2, 0., 0., 0.05 ]
";

    const FISHEYE: &str = "image_width: 1280
image_height: 960
camera_matrix:
  rows: 3
  cols: 3
  data: [400.0, 0.0, 640.5, 0.0, 401.0, 480.2, 0.0, 0.0, 1.0]
distortion_model: equidistant
distortion_coefficients: {rows: 1, cols: 4, data: [-0.01, 0.002, -0.001, 0.0001]}
";

    /// A fisheye from ROS (`equidistant`) and from OpenCV's tutorial file
    /// (`fisheye_model: 1`, a 4 × 1 matrix); an unmarked OpenCV file with
    /// 4 coefficients stays plumb_bob (`k1, k2, p1, p2`); a fisheye writes
    /// back as `equidistant` with its 4 coefficients and reads back
    /// exactly.
    #[test]
    fn fisheye_files_are_read_and_written() {
        let c = parse_camera_info(FISHEYE, "fish.yaml").unwrap();
        let k = Distortion::Equidistant([-0.01, 0.002, -0.001, 0.0001]);
        assert_eq!((c.fx, c.fy, c.distortion), (400.0, 401.0, k));
        let cv = OPENCV.replace(
            "distortion_coefficients: !!opencv-matrix\n   rows: 5",
            "fisheye_model: 1\ndistortion_coefficients: !!opencv-matrix\n   rows: 4",
        );
        let cv = cv.replace("0.1, -0.2, 0., 0., 0.05", "0.1, -0.2, 0.03, -0.004");
        let c = parse_camera_info(&cv, "cv.yaml").unwrap();
        assert_eq!(
            c.distortion,
            Distortion::Equidistant([0.1, -0.2, 0.03, -0.004])
        );
        let unmarked = cv.replace("fisheye_model: 1\n", "");
        let c = parse_camera_info(&unmarked, "cv.yaml").unwrap();
        assert_eq!(
            c.distortion,
            Distortion::PlumbBob([0.1, -0.2, 0.03, -0.004, 0.0])
        );
        let f = parse_camera_info(FISHEYE, "fish.yaml").unwrap();
        let text = render_camera_info(&f, "fish", "");
        assert!(text.contains("distortion_model: equidistant\n"), "{text}");
        assert!(text.contains("cols: 4\n"), "{text}");
        assert_eq!(parse_camera_info(&text, "r.yaml").unwrap(), f);
    }

    #[test]
    fn both_formats_are_read() {
        let c = parse_camera_info(ROS, "ros.yaml").unwrap();
        assert_eq!(
            (c.width, c.height, c.fx, c.fy, c.cx, c.cy),
            (1280, 960, 900.0, 905.0, 640.5, 480.2)
        );
        assert_eq!(
            c.distortion,
            Distortion::PlumbBob([-0.1, 0.05, 0.001, -0.0005, -0.01])
        );
        let c = parse_camera_info(OPENCV, "cv.yaml").unwrap();
        assert_eq!((c.width, c.fx, c.cy), (640, 500.0, 240.0));
        assert_eq!(
            c.distortion,
            Distortion::PlumbBob([0.1, -0.2, 0.0, 0.0, 0.05])
        );
    }

    /// A rendered camera_info reads back to the same values (17 digits),
    /// and other tools' keys are there (rectification, projection).
    #[test]
    fn rendered_camera_info_reads_back_exactly() {
        let c = Intrinsics {
            width: 1280,
            height: 960,
            fx: 1_000.123_456_789_012_3,
            fy: 999.876_543_210_987_6,
            cx: 640.1 + 1e-9,
            cy: 479.9,
            distortion: Distortion::PlumbBob([-0.081_234, 0.041, 5.1e-4, -2.9e-4, -0.011]),
        };
        let text = render_camera_info(&c, "cam", "refined\nby a test");
        assert!(text.starts_with("# refined\n# by a test\n"));
        assert!(text.contains("projection_matrix:") && text.contains("rectification_matrix:"));
        assert_eq!(parse_camera_info(&text, "r.yaml").unwrap(), c);
    }

    /// Each wrong file is refused with the file, the key and its line.
    #[test]
    fn bad_files_are_refused_with_their_place() {
        let cases = [
            (
                ROS.replace(
                    "rows: 3\n  cols: 3\n  data: [900",
                    "rows: 2\n  cols: 3\n  data: [900",
                ),
                "line 5",
                "2×3",
            ),
            (
                ROS.replace("data: [900.0", "data: [-900.0"),
                "line 5",
                "focal",
            ),
            (
                ROS.replace("plumb_bob", "rational_polynomial"),
                "line 8",
                "'rational_polynomial' is not supported",
            ),
            (
                ROS.replace("plumb_bob", "equidistant"),
                "line 10",
                "5 coefficients; equidistant (fisheye) has 4",
            ),
            (
                ROS.replace("image_width: 1280", "image_width: 0"),
                "line 1",
                "image_width",
            ),
            (ROS.replace("640.5", "6400.5"), "line 5", "principal point"),
            (ROS.replace("0.0, 905.0", "0.3, 905.0"), "line 5", "pinhole"),
            (
                ROS.replace("image_height: 960\n", ""),
                "image_height",
                "image size",
            ),
            (
                OPENCV.replace("---\n", "---\nfisheye_model: 2\n"),
                "line 3",
                "fisheye_model",
            ),
            (
                FISHEYE.replace("equidistant", "plumb_bob\nfisheye_model: 1"),
                "line 8",
                "contradicts distortion_model 'plumb_bob'",
            ),
            (
                FISHEYE.replace(
                    "cols: 4, data: [-0.01, 0.002, -0.001, 0.0001]",
                    "cols: 3, data: [-0.01, 0.002, -0.001]",
                ),
                "line 8",
                "3 coefficients; equidistant (fisheye) has 4",
            ),
            (
                ROS.replace("distortion_model: plumb_bob\n", ""),
                "line 9",
                "no 'distortion_model': name the model of the coefficients, 'distortion_model: plumb_bob' (k1, k2, p1, p2, k3) or 'distortion_model: equidistant'",
            ),
            (
                "camera_matrix: [1, 2\n".to_string(),
                "line",
                "not a camera_info",
            ),
        ];
        for (text, place, what) in cases {
            let e = parse_camera_info(&text, "cam.yaml")
                .unwrap_err()
                .to_string();
            assert!(e.starts_with("cam.yaml: "), "{e}");
            assert!(e.contains(place) && e.contains(what), "{e}");
        }
    }
}
