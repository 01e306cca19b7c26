//! `select --camera-info cam.yaml --target board.yaml --mounting …`: poses
//! chosen for a camera. Joint-space samples (`--count`, default 20,000;
//! `--pool-seed`) are kept where the camera sees the target well
//! (`activecal::pool::camera_view`: `--min-visible`, `--image-margin`,
//! `--max-view-angle`, `--distance`, at the placements `--camera-pose` and
//! `--target-pose`), and `--n` of them are chosen D-optimally on the pixel
//! Jacobian (`activecal::select::camera`). `--out design.csv` writes them:
//! one row a pose, `candidate`, the joints (radians, metres), and
//! `points_seen`, the target points the pose will see; `--out
//! design.json` the design with its figures. `--gap` scores it against
//! its visible pool's certified bound (`CameraDesign::gap`).
//! `--camera-link LINK` chooses for a camera on the robot's own link
//! (the chain from LINK to the tip, `activecal::io::urdf_branch`).

use super::camera_opts::CameraOpts;
use super::select::SelectArgs;
use activecal::collision::{CollisionSpec, Obstacle};
use activecal::io::UrdfChain;
use activecal::io::camera_info::read_camera_info;
use activecal::io::camera_target::read_target;
use activecal::model::Robot;
use activecal::pool::PoolFilter;
use activecal::pool::camera_view::CameraView;
use activecal::pool::line_of_sight::LineOfSight;
use activecal::select::camera::{CameraDesign, camera_design_in_sight};
use anyhow::{Context, Result, bail};
use serde_json::json;
use std::fmt::Write as _;
use std::path::PathBuf;

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
    let (Some(info), Some(target), Some(cp), Some(tp)) =
        (&c.camera_info, &c.target, &c.camera_pose, &c.target_pose)
    else {
        bail!("--camera-info needs --target, --camera-pose and --target-pose");
    };
    let m = match (c.mounting, &c.camera_link) {
        (Some(m), None) => m.into(),
        (None, Some(_)) => activecal::measure::camera::Mounting::EyeToHand,
        _ => bail!("--camera-info needs --mounting or --camera-link"),
    };
    let d = super::parse_list::<f64>(&c.distance, "--distance")?;
    let [lo, hi] = d[..] else {
        bail!("--distance {}: expected LO,HI (metres)", c.distance);
    };
    let target = read_target(target).context("--target")?;
    let v = CameraView {
        intrinsics: read_camera_info(info).context("--camera-info")?,
        mounting: m,
        points: target.points.iter().map(|p| [p.x, p.y, p.z]).collect(),
        face: target.face.into(),
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

/// The collision filters (`--self-collision`, `--obstacle`, `--floor`) and
/// the line of sight (`--line-of-sight`, on with any of them) of a camera
/// design.
fn sight(a: &SelectArgs, robot: &Robot) -> Result<(Vec<PoolFilter>, Option<LineOfSight>)> {
    let p = &a.pool;
    let collision = p.self_collision || !p.obstacles.is_empty() || p.floor.is_some();
    if !(collision || a.camera.line_of_sight) {
        return Ok((Vec::new(), None));
    }
    if a.camera.camera_link.is_some() {
        bail!(
            "--line-of-sight, --self-collision, --obstacle and --floor are not available with --camera-link yet (the head's chain is not the URDF chain the collision model drives)"
        );
    }
    let filters = if collision {
        p.collision_filters(robot)?
    } else if p.srdf.is_some() {
        bail!("--srdf lists pairs of links for --self-collision, which is not given");
    } else {
        Vec::new()
    };
    let Some(chain) = UrdfChain::of(robot) else {
        bail!(
            "--line-of-sight needs a URDF robot with collision geometry (--robot FILE.urdf); {} has none",
            p.robot
        );
    };
    for d in &p.package_dirs {
        if !d.exists() {
            bail!("--package-dir {}: no such directory", d.display());
        }
    }
    let obstacles = p
        .obstacles
        .iter()
        .map(|o| Obstacle::parse(o).map_err(anyhow::Error::msg))
        .collect::<Result<Vec<_>>>()?;
    let spec = CollisionSpec {
        urdf: chain.file,
        text: Some(chain.text),
        joints: chain.joints,
        lock: chain.lock,
        base: Some(chain.base),
        package_dirs: p
            .package_dirs
            .iter()
            .map(|d| d.display().to_string())
            .collect(),
        obstacles,
        floor: p.floor,
        ..CollisionSpec::default()
    };
    Ok((filters, Some(LineOfSight::new(spec))))
}

/// Options of `select` a camera design does not take (yet), refused
/// rather than ignored.
fn refuse_unused(a: &SelectArgs) -> Result<()> {
    let unused = [
        ("--report", a.report.is_some()),
        ("--existing", a.existing.is_some()),
        ("--refine", a.refine),
        ("--order", a.order.is_some()),
        ("--home", a.home.is_some()),
        ("--fixed", a.fixed.is_some()),
    ];
    if let Some((flag, _)) = unused.iter().find(|(_, used)| *used) {
        bail!(
            "{flag} is not available with --camera-info: a camera design is chosen on the pixel Jacobian of its visible pool, with --gap, --out .csv/.json and --json"
        );
    }
    Ok(())
}

/// The `--out` files: at most one `.csv` and one `.json`.
fn outputs(a: &SelectArgs) -> Result<(Option<&PathBuf>, Option<&PathBuf>)> {
    let ext = |o: &PathBuf, e: &str| o.extension().is_some_and(|x| x.eq_ignore_ascii_case(e));
    let (mut csv, mut json) = (None, None);
    for o in &a.out {
        let slot = if ext(o, "csv") {
            &mut csv
        } else if ext(o, "json") {
            &mut json
        } else {
            bail!(
                "--out {}: a camera design is written as .csv (candidate, the joints, points_seen) or .json (the design and its figures, as --json prints them)",
                o.display()
            );
        };
        if slot.replace(o).is_some() {
            bail!("--out {}: one file of each kind (.csv, .json)", o.display());
        }
    }
    for o in csv.iter().chain(json.iter()) {
        super::refuse_overwrite(o, a.force)?;
    }
    Ok((csv, json))
}

/// Runs `select` for a camera.
pub fn cmd_select_camera(a: &SelectArgs) -> Result<()> {
    refuse_unused(a)?;
    let (csv_out, json_out) = outputs(a)?;
    let robot = super::load_robot(&a.pool.robot)?;
    let robot = match &a.camera.camera_link {
        Some(link) => activecal::io::urdf_branch::camera_branch(&robot, link)
            .with_context(|| format!("--camera-link {link}"))?,
        None => robot,
    };
    let v = view(&a.camera)?;
    let (filters, los) = sight(a, &robot)?;
    let candidates = activecal::observability::generic_configurations(
        &robot,
        a.pool.count.unwrap_or(DEFAULT_SAMPLES),
        a.pool.pool_seed.unwrap_or(0),
    );
    // Candidates the collision filters keep, by their index in the samples.
    let free: Vec<usize> = (0..candidates.len())
        .filter(|&i| {
            filters
                .iter()
                .all(|f| f.keeps(&robot, &robot.nominal, &candidates[i]))
        })
        .collect();
    let collision_removed = (!filters.is_empty()).then(|| candidates.len() - free.len());
    let free_qs: Vec<Vec<f64>> = free.iter().map(|&i| candidates[i].clone()).collect();
    let settings = activecal::select::Settings::builder()
        .n(a.n)
        .seed(a.seed)
        .build()?;
    let mut d = camera_design_in_sight(&robot, &v, los.as_ref(), &free_qs, &settings)?;
    for c in &mut d.candidates {
        *c = free[*c];
    }
    let gap = if a.gap {
        let bs = activecal::bound::BoundSettings::builder()
            .solver(a.gap_solver)
            .build()?;
        Some(d.gap(&bs)?)
    } else {
        None
    };
    let names = activecal::units::joint_names(&robot);
    let mut csv = format!("candidate,{},points_seen\n", names.join(","));
    for ((q, c), s) in d.qs.iter().zip(&d.candidates).zip(&d.seen) {
        let joints: Vec<String> = q.iter().map(|v| format!("{v:.17}")).collect();
        let _ = writeln!(csv, "{c},{},{s}", joints.join(","));
    }
    let figures = json!({
        "camera_link": a.camera.camera_link,
        "mounting": v.mounting,
        "candidates": candidates.len(),
        "pool_seed": a.pool.pool_seed.unwrap_or(0),
        "visible": d.visible,
        "collision_removed": collision_removed,
        "out_of_sight": d.out_of_sight,
        "unknowns": d.names,
        "ln_det": d.ln_det,
        "log10_bound": gap.as_ref().map(|g| g.log10_bound),
        "d_efficiency": gap.as_ref().map(|g| g.d_efficiency),
        "predicted_error_mm_per_px": d.predicted_error_per_px.map(|e| 1e3 * e),
        "points_seen": d.seen,
    });
    if let Some(o) = csv_out {
        super::write_new(o, &csv, a.force)?;
    }
    let mut value = figures;
    value["robot"] = json!(a.pool.robot.head());
    value["chain"] = json!(a.pool.robot.chain);
    value["joint_names"] = json!(names);
    value["n"] = json!(d.qs.len());
    value["chosen_candidates"] = json!(d.candidates);
    value["poses"] = json!(d.qs);
    value["gap"] = json!(gap);
    if let Some(o) = json_out {
        let text = serde_json::to_string_pretty(&value)? + "\n";
        super::write_new(o, &text, a.force)?;
    }
    let written: Vec<String> = csv_out
        .iter()
        .chain(json_out.iter())
        .map(|p| p.display().to_string())
        .collect();
    value["out"] = json!(written);
    super::emit(a.json, &value, || {
        text(
            &d,
            candidates.len(),
            collision_removed,
            gap.as_ref(),
            &csv,
            &written,
        )
    })
}

/// The human-readable report of a camera design.
fn text(
    d: &CameraDesign,
    candidates: usize,
    collision_removed: Option<usize>,
    gap: Option<&activecal::bound::DesignGap>,
    csv: &str,
    written: &[String],
) -> String {
    let predicted = d.predicted_error_per_px.map_or_else(
        || "not predicted (singular design)".to_string(),
        |e| {
            format!(
                "{:.4} mm per px of pixel noise σ (RMS over 1,000 configurations)",
                1e3 * e
            )
        },
    );
    let mut s = String::new();
    if let Some(c) = collision_removed {
        let _ = writeln!(
            s,
            "collision: removed {c} of {candidates} sampled configurations"
        );
    }
    let (well, blocked) = d.out_of_sight.map_or((String::new(), String::new()), |o| {
        (
            " and in sight".to_string(),
            format!(" ({o} more seen well, but the robot's collision geometry blocks a ray)"),
        )
    });
    let _ = write!(
        s,
        "camera: the target is seen well{well} at {} of {candidates} sampled configurations{blocked}\nchose {} poses on the pixel Jacobian ({} unknowns): ln det XᵀX = {:.3} (unit pixel noise)\n",
        d.visible,
        d.qs.len(),
        d.names.len(),
        d.ln_det,
    );
    if let Some(g) = gap {
        let _ = writeln!(
            s,
            "log10 det XᵀX {:.4}  log10 bound {:.4}  D-efficiency >= {:.6} (the visible pool's certified bound)",
            g.log10_oid.unwrap_or(f64::NEG_INFINITY),
            g.log10_bound,
            g.d_efficiency
        );
    }
    let seen: Vec<String> = d.seen.iter().map(usize::to_string).collect();
    let _ = writeln!(
        s,
        "predicted true error: {predicted}\npoints seen per pose: {}",
        seen.join(", ")
    );
    if written.is_empty() {
        s += csv;
    }
    for w in written {
        let _ = writeln!(s, "wrote {w}");
    }
    s
}
