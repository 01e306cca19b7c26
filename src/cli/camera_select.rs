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
    CameraSelectPlan, Candidates, DEFAULT_SAMPLES, design_outputs, select_camera,
};
use activecal::io::camera_info::read_camera_info;
use activecal::io::camera_target::read_target;
use activecal::model::Robot;
use activecal::options::CameraView;
use anyhow::{Context, Result, bail};

pub use activecal::experiment::camera_select::DEFAULT_PIXEL_NOISE;

/// The camera view the options describe.
fn view(c: &CameraOpts) -> Result<CameraView> {
    let (Some(info), Some(target), Some(cp), Some(tp)) =
        (&c.camera_info, &c.target, &c.camera_pose, &c.target_pose)
    else {
        bail!("--camera-info needs --target, --camera-pose and --target-pose");
    };
    let m = match (c.mounting, &c.camera_link) {
        (Some(m), None) => m,
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
        camera: super::six("--camera-pose", cp)?,
        target: super::six("--target-pose", tp)?,
        min_fraction: c.min_visible,
        margin_px: c.image_margin,
        max_view_angle: c.max_view_angle.to_radians(),
        distance: [lo, hi],
    };
    Ok(v)
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

/// Runs `select` for a camera.
pub fn cmd_select_camera(a: &SelectArgs) -> Result<()> {
    check_options(a)?;
    super::run_files::check(&super::select::select_files(a), a.force)?;
    let outs: Vec<_> = a.out.iter().map(|p| super::out_file(p)).collect();
    let outs = design_outputs(&outs)?;
    let robot = super::load_robot(&a.pool.robot)?;
    let listed_robot = match &a.camera.camera_link {
        Some(link) => activecal::io::urdf_branch::camera_branch(&robot, link)
            .with_context(|| format!("--camera-link {link}"))?,
        None => robot.clone(),
    };
    let plan = CameraSelectPlan {
        view: view(&a.camera)?,
        camera_link: a.camera.camera_link.clone(),
        collision: a.pool.collision_choice(true)?,
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
    for o in &outs {
        sel.write(*o, a.force)?;
    }
    let mut written: Vec<String> = outs.iter().map(|o| o.path.display().to_string()).collect();
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
