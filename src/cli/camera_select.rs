//! `select --camera-info cam.yaml --target board.yaml --mounting …`: poses
//! chosen for a camera. Joint-space samples (`--count`, default 20,000;
//! `--pool-seed`) are kept where the camera sees the target well
//! (`activecal::pool::camera_view`: `--min-visible`, `--image-margin`,
//! `--max-view-angle`, `--distance`, at the placements `--camera-pose` and
//! `--target-pose`), and `--n` of them are chosen D-optimally on the pixel
//! Jacobian (`activecal::select::camera`). `--out design.csv` writes them:
//! one row a pose, `candidate`, the joints (radians, metres), and
//! `points_seen`, the target points the pose will see.

use super::camera_opts::CameraOpts;
use super::select::SelectArgs;
use activecal::io::camera_info::read_camera_info;
use activecal::io::camera_target::read_target;
use activecal::pool::camera_view::CameraView;
use activecal::select::camera::camera_design;
use anyhow::{Context, Result, bail};
use serde_json::json;
use std::fmt::Write as _;

/// Joint-space samples when `--count` is not given.
const DEFAULT_SAMPLES: usize = 20_000;

fn six(flag: &str, s: &str) -> Result<[f64; 6]> {
    let v = super::parse_list::<f64>(s, flag)?;
    v.try_into().map_err(|_| {
        anyhow::anyhow!(
            "{flag} {s}: expected X,Y,Z,ROLL,PITCH,YAW (six numbers, metres and radians)"
        )
    })
}

/// The camera view the options describe.
fn view(c: &CameraOpts) -> Result<CameraView> {
    let (Some(info), Some(target), Some(m), Some(cp), Some(tp)) = (
        &c.camera_info,
        &c.target,
        c.mounting,
        &c.camera_pose,
        &c.target_pose,
    ) else {
        bail!("--camera-info needs --target, --mounting, --camera-pose and --target-pose");
    };
    let d = super::parse_list::<f64>(&c.distance, "--distance")?;
    let [lo, hi] = d[..] else {
        bail!("--distance {}: expected LO,HI (metres)", c.distance);
    };
    let v = CameraView {
        intrinsics: read_camera_info(info).context("--camera-info")?,
        mounting: m.into(),
        points: read_target(target)
            .context("--target")?
            .points
            .iter()
            .map(|p| [p.x, p.y, p.z])
            .collect(),
        camera: six("--camera-pose", cp)?,
        target: six("--target-pose", tp)?,
        min_fraction: c.min_visible,
        margin_px: c.image_margin,
        max_view_angle: c.max_view_angle.to_radians(),
        distance: [lo, hi],
    };
    v.validate()
        .map_err(|e| anyhow::anyhow!("camera view: {e}"))?;
    Ok(v)
}

/// Runs `select` for a camera.
pub fn cmd_select_camera(a: &SelectArgs) -> Result<()> {
    let out = match &a.out[..] {
        [] => None,
        [o] if o.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv")) => Some(o),
        _ => bail!(
            "--out: a camera design is written as one .csv (candidate, the joints, points_seen)"
        ),
    };
    if let Some(o) = out {
        super::refuse_overwrite(o, a.force)?;
    }
    let robot = super::load_robot(&a.pool.robot)?;
    let v = view(&a.camera)?;
    let candidates = activecal::observability::generic_configurations(
        &robot,
        a.pool.count.unwrap_or(DEFAULT_SAMPLES),
        a.pool.pool_seed.unwrap_or(0),
    );
    let settings = activecal::select::Settings::builder()
        .n(a.n)
        .seed(a.seed)
        .build()?;
    let d = camera_design(&robot, &v, &candidates, &settings)?;
    let names = activecal::units::joint_names(&robot);
    let mut csv = format!("candidate,{},points_seen\n", names.join(","));
    for ((q, c), s) in d.qs.iter().zip(&d.candidates).zip(&d.seen) {
        let joints: Vec<String> = q.iter().map(|v| format!("{v:.17}")).collect();
        let _ = writeln!(csv, "{c},{},{s}", joints.join(","));
    }
    if let Some(o) = out {
        super::write_new(o, &csv, a.force)?;
    }
    let value = json!({
        "robot": robot.name,
        "candidates": candidates.len(),
        "visible": d.visible,
        "n": d.qs.len(),
        "unknowns": d.names,
        "ln_det": d.ln_det,
        "predicted_error_mm_per_px": d.predicted_error_per_px.map(|e| 1e3 * e),
        "poses": d.qs,
        "points_seen": d.seen,
        "out": out.map(|p| p.display().to_string()),
    });
    super::emit(a.json, &value, || {
        let predicted = d.predicted_error_per_px.map_or_else(
            || "not predicted (singular design)".to_string(),
            |e| {
                format!(
                    "{:.4} mm per px of pixel noise σ (RMS over 1,000 configurations)",
                    1e3 * e
                )
            },
        );
        let mut s = format!(
            "camera: the target is seen well at {} of {} sampled configurations\nchose {} poses on the pixel Jacobian ({} unknowns): ln det XᵀX = {:.3} (unit pixel noise)\npredicted true error: {predicted}\npoints seen per pose: {}\n",
            d.visible,
            candidates.len(),
            d.qs.len(),
            d.names.len(),
            d.ln_det,
            d.seen
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        );
        match out {
            None => s += &csv,
            Some(o) => {
                let _ = writeln!(s, "wrote {}", o.display());
            }
        }
        s
    })
}
