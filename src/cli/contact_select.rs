//! `select --point NAME=x,y,z`: the configurations to record for sockets
//! (calibration from contacts, no instrument). Parses the sockets and the
//! options that apply, renders the design; the work is in
//! `activecal::identify::contact::socket_design`.

use super::select::SelectArgs;
use activecal::identify::contact::lengths::distance_beyond_reach;
use activecal::identify::contact::select::Socket;
use activecal::identify::contact::socket_design::{SocketDesignSettings, design_for_sockets};
use activecal::io::design_formats::DesignFormat;
use activecal::measure::contact::KnownDistance;
use activecal::model::MeasurementKind;
use activecal::write::contact_design;
use anyhow::{Result, bail};

/// Joint-space samples projected onto each socket when `--count` is not
/// given.
pub const DEFAULT_SAMPLES: usize = 1000;

/// Parses one `--point NAME=x,y,z` (base frame, metres).
fn parse_socket(s: &str) -> Result<Socket> {
    match super::contact::named_numbers::<3>(s) {
        Some((name, position)) if position.iter().all(|c| c.is_finite()) => {
            Ok(Socket { name, position })
        }
        _ => anyhow::bail!(
            "--point {s}: expected NAME=X,Y,Z (a point name and its position in the base frame, metres, e.g. front_left/0=0.48,0.23,0.02)"
        ),
    }
}

/// The `--point-distance A,B=METRES` between sockets, as indices into
/// `sockets`; a name that is no socket's is refused, naming the sockets.
/// A distance beyond twice the robot's reach is refused as `calibrate`
/// refuses it ([`distance_beyond_reach`], a length in millimetres named as
/// such).
fn known_distances(
    robot: &activecal::model::Robot,
    sockets: &[Socket],
    given: &[String],
) -> Result<Vec<KnownDistance>> {
    let names: Vec<&str> = sockets.iter().map(|s| s.name.as_str()).collect();
    given
        .iter()
        .map(|s| {
            let d = super::contact::parse_distance(s)?;
            let index = |n: &str| {
                names.iter().position(|m| *m == n).ok_or_else(|| {
                    anyhow::anyhow!(
                        "--point-distance {s}: no --point is named '{n}' (the points: {})",
                        names.join(", ")
                    )
                })
            };
            let (ia, ib) = (index(&d.a)?, index(&d.b)?);
            if ia == ib || !(d.metres.is_finite() && d.metres > 0.0) {
                bail!(
                    "--point-distance {s}: a distance needs two different points and a finite length > 0 (metres)"
                );
            }
            if let Some(why) = distance_beyond_reach(robot, &d.a, &d.b, d.metres) {
                bail!("--point-distance: {why}");
            }
            Ok(KnownDistance {
                a: ia,
                b: ib,
                metres: d.metres,
            })
        })
        .collect()
}

/// Runs `select --point ...`.
pub fn cmd_select_points(a: &SelectArgs) -> Result<()> {
    let sockets: Vec<Socket> = a
        .points
        .iter()
        .map(|s| parse_socket(s))
        .collect::<Result<_>>()?;
    super::select::select_files(a).check(a.force)?;
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
    if !matches!(robot.measurement, MeasurementKind::Point) {
        bail!(
            "--point: the tool point of {} is a measured point; use the robot without :pose",
            robot.name
        );
    }
    let distances = known_distances(&robot, &sockets, &a.point_distance)?;
    let filters = a.pool.collision_filters(&robot)?;
    let settings = SocketDesignSettings {
        n: a.n,
        samples: a.pool.count.unwrap_or(DEFAULT_SAMPLES),
        margin: margin_deg.to_radians(),
        sample_seed: a.pool.pool_seed.unwrap_or(0),
        draw_seed: a.seed,
        filters,
        distances,
        ..SocketDesignSettings::default()
    };
    let d = design_for_sockets(&robot, robot.params(a.pool.params), &sockets, &settings)?;
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
