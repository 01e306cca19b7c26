//! `select --point NAME=x,y,z`: the configurations to record for sockets
//! (calibration from contacts, no instrument). Parses the sockets and the
//! options that apply, renders the design; the work is in
//! `activecal::experiment::socket_design`.

use super::select::SelectArgs;
use activecal::experiment::socket_design::{
    DEFAULT_SAMPLES, Socket, SocketDesignError, SocketDesignSettings, design,
};
use activecal::io::design_formats::DesignFormat;
use activecal::write::contact_design;
use anyhow::{Result, bail};

/// Parses one `--point NAME=x,y,z` (base frame, metres).
fn parse_socket(s: &str) -> Result<Socket> {
    match activecal::data::contacts::named_numbers::<3>(s) {
        Some((name, position)) if position.iter().all(|c| c.is_finite()) => {
            Ok(Socket { name, position })
        }
        _ => anyhow::bail!(
            "--point {s}: expected NAME=X,Y,Z (a point name and its position in the base frame, metres, e.g. front_left/0=0.48,0.23,0.02)"
        ),
    }
}

/// A refused input of the design, named as the command line gives it
/// (`given` the `--point-distance` arguments).
fn named(e: SocketDesignError, given: &[String]) -> anyhow::Error {
    match e {
        SocketDesignError::ToolNotAPoint { robot } => anyhow::anyhow!(
            "--point: the tool point of {robot} is a measured point; use the robot without :pose"
        ),
        SocketDesignError::UnknownPoint {
            distance,
            name,
            points,
        } => anyhow::anyhow!(
            "--point-distance {}: no --point is named '{name}' (the points: {})",
            given[distance],
            points.join(", ")
        ),
        SocketDesignError::BadDistance { distance } => {
            anyhow::anyhow!("--point-distance {}: {e}", given[distance])
        }
        SocketDesignError::BeyondReach { .. } => anyhow::anyhow!("--point-distance: {e}"),
        SocketDesignError::Design(e) => e.into(),
    }
}

/// Runs `select --point ...`.
pub fn cmd_select_points(a: &SelectArgs) -> Result<()> {
    let sockets: Vec<Socket> = a
        .points
        .iter()
        .map(|s| parse_socket(s))
        .collect::<Result<_>>()?;
    super::run_files::check(&super::select::select_files(a), a.force)?;
    super::select::check_out_formats(&a.out)?;
    let margin_deg = a
        .pool
        .margin
        .unwrap_or(super::pool_opts::DEFAULT_MARGIN_DEG);
    if !(margin_deg.is_finite() && margin_deg >= 0.0) {
        bail!("--margin {margin_deg}: a margin is a finite number of degrees ≥ 0");
    }
    let described = super::load_description(&a.pool.robot)?;
    let robot = described.robot;
    let given = a
        .point_distance
        .iter()
        .map(|s| super::contact::parse_distance(s))
        .collect::<Result<Vec<_>>>()?;
    let filters = a.pool.collision_filters(&robot)?;
    let settings = SocketDesignSettings {
        n: a.n,
        samples: a.pool.count.unwrap_or(DEFAULT_SAMPLES),
        margin: margin_deg.to_radians(),
        sample_seed: a.pool.pool_seed.unwrap_or(0),
        draw_seed: a.seed,
        filters,
        ..SocketDesignSettings::default()
    };
    let d = design(
        &robot,
        robot.params(a.pool.params),
        &sockets,
        &given,
        settings,
    )
    .map_err(|e| named(e, &a.point_distance))?;
    for out in &a.out {
        let text = match DesignFormat::of(out)? {
            DesignFormat::Json => contact_design::to_json(&d),
            DesignFormat::Csv => contact_design::to_csv(&d),
            DesignFormat::Yaml => contact_design::to_yaml(&d)?,
        };
        super::write_new(out, &text, a.force)?;
    }
    super::emit_report(a.json, &d, || {
        activecal::render::socket_design_text::socket_design_text(
            &d,
            super::pool_opts::SRDF_HINT,
            " (--point-distance)",
        )
    })
}
