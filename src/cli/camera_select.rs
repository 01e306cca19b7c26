//! `select --camera-info cam.yaml --target board.yaml --mounting …`: poses
//! chosen for a camera. Joint-space samples (`--count`, default 20,000;
//! `--pool-seed`), or the rows of `--pool file:PATH`, are kept where the camera sees the target well
//! (the camera's view, `activecal::options::CameraView`: `--min-visible`, `--image-margin`,
//! `--max-view-angle`, `--distance`, at the placements `--camera-pose` and
//! `--target-pose`), and `--n` of them are chosen D-optimally on the pixel
//! Jacobian (`activecal::experiment::camera_select`). `--out design.csv` writes them:
//! one row a pose, `candidate`, the joints (radians, metres), and
//! `points_seen`, the target points the pose will see; `--out
//! design.json` the design with its figures. `--gap` scores it against
//! its visible pool's certified bound (`CameraDesign::gap`).
//! `--camera-link LINK` chooses for a camera on the robot's own link
//! (the chain from LINK to the tip, `activecal::io::urdf_branch`).

use super::camera_opts::CameraOpts;
use super::pool_opts::PoolKind;
use super::select::SelectArgs;
use activecal::experiment::camera_select::{
    CameraSelectPlan, Candidates, DEFAULT_SAMPLES, select_camera,
};
use activecal::io::camera_info::read_camera_info;
use activecal::io::camera_target::read_target;
use activecal::io::collision_choice::CollisionChoice;
use activecal::model::Robot;
use activecal::options::CameraView;
use anyhow::{Context, Result, bail};
use std::path::PathBuf;

pub use activecal::experiment::camera_select::DEFAULT_PIXEL_NOISE;

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
        (None, Some(_)) => activecal::options::Mounting::EyeToHand,
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
    Ok(v)
}

/// What the collision checks (`--self-collision`, `--obstacle`, `--floor`,
/// as for any pool) ask for; without one, the `--package-dir`s the line of
/// sight finds meshes in (checked to exist) and no `--srdf`.
fn collision(a: &SelectArgs) -> Result<CollisionChoice> {
    let p = &a.pool;
    if p.self_collision || !p.obstacles.is_empty() || p.floor.is_some() {
        return p.collision_choice();
    }
    if p.srdf.is_some() {
        bail!("--srdf lists pairs of links for --self-collision, which is not given");
    }
    for d in &p.package_dirs {
        if !d.exists() {
            bail!("--package-dir {}: no such directory", d.display());
        }
    }
    Ok(CollisionChoice {
        package_dirs: p
            .package_dirs
            .iter()
            .map(|d| d.display().to_string())
            .collect(),
        ..CollisionChoice::default()
    })
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
fn candidates(a: &SelectArgs, robot: &Robot) -> Result<Candidates> {
    Ok(match &a.pool.pool {
        PoolKind::File(p) => {
            let c = activecal::io::configurations::read_configurations_in(
                p,
                robot,
                a.pool.units.units(),
            )
            .with_context(|| format!("--pool file:{}", p.display()))?;
            for n in &c.notes {
                super::diag(&format!("note: {n}"));
            }
            Candidates::Listed(c.qs)
        }
        _ => Candidates::Sampled {
            count: a.pool.count.unwrap_or(DEFAULT_SAMPLES),
            seed: a.pool.pool_seed.unwrap_or(0),
        },
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
    let listed_robot = match &a.camera.camera_link {
        Some(link) => activecal::io::urdf_branch::camera_branch(&robot, link)
            .with_context(|| format!("--camera-link {link}"))?,
        None => robot.clone(),
    };
    let plan = CameraSelectPlan {
        view: view(&a.camera)?,
        camera_link: a.camera.camera_link.clone(),
        collision: collision(a)?,
        line_of_sight: a.camera.line_of_sight,
        candidates: candidates(a, &listed_robot)?,
        settings: activecal::options::SelectSettings::builder()
            .n(a.n)
            .seed(a.seed)
            .build()?,
        gap: a.gap.then(|| bound(a)).transpose()?,
        pixel_noise: a.camera.pixel_noise,
        robot_name: a.pool.robot.head(),
        chain: a.pool.robot.chain.clone(),
    };
    let sel = select_camera(&robot, plan).map_err(|e| match e {
        activecal::experiment::ExperimentError::Input(e @ activecal::Error::TooLarge { .. }) => {
            anyhow::Error::from(e).context(pool_label(a))
        }
        e => e.into(),
    })?;
    let curve = match &a.report {
        Some(_) => Some(sel.curve(
            bound(a)?,
            a.camera.pixel_noise.unwrap_or(DEFAULT_PIXEL_NOISE),
            a.target_error,
        )?),
        None => None,
    };
    let csv = sel.design_csv();
    if let Some(o) = csv_out {
        super::write_new(o, &csv, a.force)?;
    }
    let report = &sel.report;
    if let Some(o) = json_out {
        let text = serde_json::to_string_pretty(&report)? + "\n";
        super::write_new(o, &text, a.force)?;
    }
    let mut written: Vec<String> = csv_out
        .iter()
        .chain(json_out.iter())
        .map(|p| p.display().to_string())
        .collect();
    if let (Some(dir), Some(c)) = (&a.report, &curve) {
        sel.write_report(dir, c, &written, a.camera.pixel_noise.is_none())?;
        written.push(dir.display().to_string());
    }
    let mut report = sel.report.clone();
    report.out = Some(written.clone());
    super::emit_report(a.json, &report, || sel.text(&written, curve.as_ref()))
}

/// The certified bound's settings of `--gap` and `--report`'s curve
/// (`--gap-solver`).
fn bound(a: &SelectArgs) -> Result<activecal::options::BoundSettings> {
    Ok(activecal::options::BoundSettings::builder()
        .solver(a.gap_solver)
        .build()?)
}
