//! `select --camera-info cam.yaml --target board.yaml --mounting …`: poses
//! chosen for a camera. Joint-space samples (`--count`, default 20,000;
//! `--pool-seed`), or the rows of `--pool file:PATH`, are kept where the camera sees the target well
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
use super::pool_opts::PoolKind;
use super::select::SelectArgs;
use activecal::collision::Obstacle;
use activecal::io::UrdfChain;
use activecal::io::camera_info::read_camera_info;
use activecal::io::camera_target::read_target;
use activecal::io::collision_choice::CollisionChoice;
use activecal::model::Robot;
use activecal::pool::PoolFilter;
use activecal::pool::camera_view::CameraView;
use activecal::pool::line_of_sight::LineOfSight;
use activecal::report::{CameraDesignReport, CameraPoolInfo};
use activecal::select::camera::{CameraDesign, camera_design_filtered};
use anyhow::{Context, Result, bail};
use serde_json::json;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Joint-space samples when `--count` is not given.
const DEFAULT_SAMPLES: usize = 20_000;

/// The pixel noise σ of `--report`'s curve when `--pixel-noise` is not
/// given, px: a corner detector's typical sub-pixel error (OpenCV's
/// `cornerSubPix` on a sharp checkerboard gives 0.1–0.5 px), and the σ of
/// the project's camera examples.
pub const DEFAULT_PIXEL_NOISE: f64 = 0.3;

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
/// design. With `--camera-link` the chain's joints drive the whole tree by
/// name, obstacles and the floor are in the tree's root link, and the rays
/// leave from the camera's link.
fn sight(a: &SelectArgs, robot: &Robot) -> Result<(Vec<PoolFilter>, Option<LineOfSight>)> {
    let p = &a.pool;
    let collision = p.self_collision || !p.obstacles.is_empty() || p.floor.is_some();
    if !(collision || a.camera.line_of_sight) {
        return Ok((Vec::new(), None));
    }
    let root = match &a.camera.camera_link {
        Some(link) => Some((link.as_str(), activecal::io::urdf_branch::tree_root(robot)?)),
        None => None,
    };
    let mut chain = UrdfChain::of(robot);
    if let (Some((_, r)), Some(c)) = (&root, chain.as_mut()) {
        c.base.clone_from(r);
    }
    let filters = if collision {
        p.collision_filters_on(chain.clone())?
    } else if p.srdf.is_some() {
        bail!("--srdf lists pairs of links for --self-collision, which is not given");
    } else {
        Vec::new()
    };
    let Some(chain) = chain else {
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
    let choice = CollisionChoice {
        package_dirs: p
            .package_dirs
            .iter()
            .map(|d| d.display().to_string())
            .collect(),
        obstacles: p
            .obstacles
            .iter()
            .map(|o| Obstacle::parse(o).map_err(anyhow::Error::msg))
            .collect::<Result<Vec<_>>>()?,
        floor: p.floor,
        ..CollisionChoice::default()
    };
    Ok((filters, Some(choice.line_of_sight(chain, root))))
}

/// A `--pixel-noise` that is no σ, and a `--pool` a camera design does
/// not sample from, refused before any work (the options a camera design
/// does not take are refused by `acts_on::SELECT`).
fn check_options(a: &SelectArgs) -> Result<()> {
    if let Some(px) = a.camera.pixel_noise
        && !(px.is_finite() && px > 0.0)
    {
        bail!("--pixel-noise {px}: the pixel noise σ must be a finite number > 0 (px)");
    }
    let given = |id: &str| a.given.0.iter().find(|(i, _)| i == id).map(|(_, f)| f);
    match &a.pool.pool {
        PoolKind::File(p) => {
            if let Some(f) = given("count").or_else(|| given("pool_seed")) {
                bail!(
                    "{f}: not used with --pool file:{} (its rows are the candidates; --count and --pool-seed draw joint-space samples)",
                    p.display()
                );
            }
        }
        PoolKind::Lattice | PoolKind::Sobol if given("pool").is_some() => bail!(
            "--pool {}: a camera design's candidates are --count uniform joint-space samples (--pool random, the default) or the rows of --pool file:PATH",
            if a.pool.pool == PoolKind::Sobol {
                "sobol"
            } else {
                "lattice"
            }
        ),
        _ => {
            if let Some(f) = given("angle_unit").or_else(|| given("length_unit")) {
                bail!(
                    "{f}: the unit of a --pool file:'s joint values; a camera design without one reads none"
                );
            }
        }
    }
    Ok(())
}

/// The candidate configurations: the rows of `--pool file:` (in its
/// units), else `--count` uniform samples within the joint limits
/// (`--pool-seed`).
fn candidates(a: &SelectArgs, robot: &Robot) -> Result<Vec<Vec<f64>>> {
    Ok(match &a.pool.pool {
        PoolKind::File(p) => {
            let c = activecal::pool::file::read_configurations_in(p, robot, a.pool.units.units())
                .with_context(|| format!("--pool file:{}", p.display()))?;
            for n in &c.notes {
                super::diag(&format!("note: {n}"));
            }
            c.qs
        }
        _ => {
            let count = a.pool.count.unwrap_or(DEFAULT_SAMPLES);
            activecal::resources::check_alloc::<f64>(
                &format!("--count {count}: the candidate configurations"),
                count.saturating_mul(robot.dof() + 3),
            )?;
            activecal::observability::generic_configurations(
                robot,
                count,
                a.pool.pool_seed.unwrap_or(0),
            )
        }
    })
}

/// The option that made the candidates, for messages: `--pool file:F` or
/// `--count N`.
fn pool_label(a: &SelectArgs) -> String {
    match &a.pool.pool {
        PoolKind::File(p) => format!("--pool file:{}", p.display()),
        _ => format!("--count {}", a.pool.count.unwrap_or(DEFAULT_SAMPLES)),
    }
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
    Ok((csv, json))
}

/// Runs `select` for a camera.
pub fn cmd_select_camera(a: &SelectArgs) -> Result<()> {
    check_options(a)?;
    super::select::select_files(a).check(a.force)?;
    let (csv_out, json_out) = outputs(a)?;
    let robot = super::load_robot(&a.pool.robot)?;
    let robot = match &a.camera.camera_link {
        Some(link) => activecal::io::urdf_branch::camera_branch(&robot, link)
            .with_context(|| format!("--camera-link {link}"))?,
        None => robot,
    };
    let v = view(&a.camera)?;
    let (filters, los) = sight(a, &robot)?;
    let candidates = candidates(a, &robot)?;
    let settings = activecal::select::Settings::builder()
        .n(a.n)
        .seed(a.seed)
        .build()?;
    let (d, collision_removed) =
        camera_design_filtered(&robot, &v, &filters, los.as_ref(), &candidates, &settings)
            .map_err(|e| match e {
                e @ activecal::Error::TooLarge { .. } => {
                    anyhow::Error::from(e).context(pool_label(a))
                }
                e => e.into(),
            })?;
    let gap = if a.gap {
        let bs = activecal::bound::BoundSettings::builder()
            .solver(a.gap_solver)
            .build()?;
        Some(d.gap(&bs)?)
    } else {
        None
    };
    let curve = match &a.report {
        Some(_) => Some(curve(a, &settings, &d)?),
        None => None,
    };
    let names = activecal::units::joint_names(&robot);
    let mut csv = format!("candidate,{},points_seen\n", names.join(","));
    for ((q, c), s) in d.qs.iter().zip(&d.candidates).zip(&d.seen) {
        let joints: Vec<String> = q.iter().map(|v| format!("{v:.17}")).collect();
        let _ = writeln!(csv, "{c},{},{s}", joints.join(","));
    }
    if let Some(o) = csv_out {
        super::write_new(o, &csv, a.force)?;
    }
    let pool = CameraPoolInfo {
        robot: a.pool.robot.head(),
        chain: a.pool.robot.chain.clone(),
        camera_link: a.camera.camera_link.clone(),
        candidates: candidates.len(),
        pool_seed: a.pool.pool_seed.unwrap_or(0),
        collision_removed,
        pixel_noise: a.camera.pixel_noise,
    };
    let report = CameraDesignReport::new(&d, pool, v.mounting, names.clone(), gap.clone());
    let mut value = serde_json::to_value(&report)?;
    if let Some(o) = json_out {
        let text = serde_json::to_string_pretty(&value)? + "\n";
        super::write_new(o, &text, a.force)?;
    }
    let written: Vec<String> = csv_out
        .iter()
        .chain(json_out.iter())
        .map(|p| p.display().to_string())
        .collect();
    let mut written = written;
    let rendered = |written: &[String]| {
        let mut s = text(
            &d,
            candidates.len(),
            collision_removed,
            gap.as_ref(),
            a.camera.pixel_noise,
            &csv,
            written,
        );
        if let Some(r) = curve.as_ref().and_then(|c| c.recommended.as_ref()) {
            s += &activecal::render::folder::recommendation_text(r);
        }
        s
    };
    if let (Some(dir), Some(c)) = (&a.report, &curve) {
        written.push(dir.display().to_string());
        activecal::render::folder::camera_selection(
            dir,
            &robot,
            &names,
            &d,
            &rendered(&written[..written.len() - 1]),
            &value,
            c,
            a.camera.pixel_noise.is_none(),
        )?;
    }
    value["out"] = json!(written);
    super::emit(a.json, &value, || rendered(&written))
}

/// `--report`'s "how many poses" curve of a camera design, its pose ids
/// those of the sampled configurations.
fn curve(
    a: &SelectArgs,
    settings: &activecal::select::Settings,
    d: &CameraDesign,
) -> Result<activecal::how_many::PoseCountCurve> {
    let mut cs = activecal::how_many::CurveSettings::new(
        settings.clone(),
        a.camera.pixel_noise.unwrap_or(DEFAULT_PIXEL_NOISE),
    );
    cs.bound = activecal::bound::BoundSettings::builder()
        .solver(a.gap_solver)
        .build()?;
    cs.also = vec![a.n];
    cs.target_mm = a.target_error;
    Ok(d.how_many(&cs)?)
}

/// The human-readable report of a camera design.
fn text(
    d: &CameraDesign,
    candidates: usize,
    collision_removed: Option<usize>,
    gap: Option<&activecal::bound::DesignGap>,
    pixel_noise: Option<f64>,
    csv: &str,
    written: &[String],
) -> String {
    let predicted = d.predicted_error_per_px.map_or_else(
        || "not predicted (singular design)".to_string(),
        |e| {
            let at = pixel_noise.map_or(String::new(), |s| {
                format!(", {:.4} mm at σ = {s} px", 1e3 * e * s)
            });
            format!(
                "{:.4} mm per px of pixel noise σ (RMS over 1,000 configurations){at}",
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
