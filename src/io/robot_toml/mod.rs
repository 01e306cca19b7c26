//! Robot description files (TOML): frames, real and nominal parameter
//! tables, unknowns, joint limits, the measurement and an optional sensor
//! visibility region.
//!
//! ```toml
//! name = "puma560"            # optional; default: the file name
//! measurement = "point"       # "point" (3 rows per pose), "pose" (6 rows), "markers" (3 per marker) or a registered sensor's name
//! # orientation_scale = 0.29  # pose only: metres per radian, σ_position / σ_orientation
//! # unknowns = "auto"         # choose identifiable unknowns automatically
//!
//! [visibility]                # optional: see activecal::measure::Visibility
//! kind = "box"
//! min = [-30.0, -30.0, -30.0]
//! max = [30.0, 30.0, 30.0]
//!
//! [[frame]]                   # frames in chain order, measurement frame first
//! label = "a"                 # used in parameter names: gamma_a, d_3, …
//! convention = "hayati"       # "dh" or "hayati"
//! joint = "fixed"             # "revolute", "prismatic" or "fixed"
//! #         gamma      alpha   a     d    beta   (radians, metres)
//! real    = [1.5708,   0.0314, 20.0, 0.0, 0.0314]
//! nominal = [1.6360,   0.1572, 19.882, 0.0, -0.0123]
//! unknowns = ["gamma", "alpha", "a", "beta"]
//!
//! [[frame]]
//! label = "0"
//! convention = "dh"
//! joint = "revolute"          # joints are numbered in frame order: q1, q2, …
//! limits_deg = [-250, 70]     # or limits = [lo, hi] in radians (metres if prismatic)
//! real    = [0.0, -1.5708, 0.0, 0.6858]       # a DH row may omit beta
//! nominal = [-0.0367, -1.4524, 0.0603, 0.6713]
//! unknowns = ["gamma", "alpha", "a", "d"]
//! ```
//!
//! With `measurement = "markers"`, one `[[marker]]` table per marker gives
//! its offset in the last frame (metres), e.g. `nominal = [0.0, 0.05,
//! 0.45]` and optionally `real = […]` (default: the nominal); every offset
//! is an unknown of its own (see [`crate::measure::markers`]). `calibrate
//! --out` writes the estimated offsets this way.
//!
//! Instead of frames, a file may import a URDF: `urdf = "arm.urdf"` (relative
//! to the file), with optional `base = "link"` (default: the URDF's root),
//! `tip = "link"` (required when the URDF is a tree), a table `[lock]` of
//! joints made fixed at a value (`torso_lift_joint = 0.15`, radians or
//! metres), `measurement`, `name` and `visibility`; its unknowns are chosen
//! automatically (see [`super::urdf`]).
//!
//! For calibration from contacts (a measurement file with a `point` or
//! `plane` column), `[[distance]]` tables give known distances between
//! points (`a = "front_left/0"`, `b = "front_left/1"`, `metres = 0.05`)
//! and `[[plane]]` tables known planes (`name = "table"`, `normal = [0, 0,
//! 1]`, `offset = 0.02`: `normal · x = offset` in the base frame, metres),
//! as `--point-distance` and `--plane` do ([`super::ContactSetup`]).
//!
//! Every problem is an [`Error::Parse`] naming the file and the place:
//! TOML syntax, unknown keys, missing or mistyped fields (with the TOML
//! parser's line and column), and — with line, column and frame label — a
//! non-finite value, a duplicate frame label, wrong row or limit lengths,
//! inverted limits, an unknown symbol, no unknowns, and unknowns that are not
//! identifiable ([`Robot::check_identifiable`]).

mod contacts;
mod frames;
mod spec;
mod write;

pub use spec::{MAX_ABS, MAX_FRAMES};
pub use write::{description_to_toml, to_toml};

use super::Description;
use crate::error::{Compact, Error, Result};
use crate::measure::Visibility;
use crate::model::{MeasurementKind, ParamTable, Robot};
use frames::frames_of;
use spec::{Ctx, FileSpec, MarkerSpec};
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

/// Reads and checks a robot description file (see the module docs).
pub fn load(path: &Path) -> Result<Robot> {
    load_description(path).map(|d| d.robot)
}

/// Reads and checks a robot description file, with its visibility region.
pub fn load_description(path: &Path) -> Result<Description> {
    let text = crate::io::read::read_text(path)?;
    parse_description(&text, &path.display().to_string(), path.parent())
}

/// Parses and checks a description's robot (see [`parse_description`]).
pub fn parse(text: &str, origin: &str, dir: Option<&Path>) -> Result<Robot> {
    parse_description(text, origin, dir).map(|d| d.robot)
}

/// Parses and checks a description. `origin` names it in errors (and gives
/// the default robot name, its file stem); `dir` is where a `urdf = …` path
/// is relative to (the current directory if `None`).
///
/// ```
/// use activecal::io::robot_toml as file;
/// use activecal::model::Robot;
/// let text = file::to_toml(&Robot::stanford());
/// let r = file::parse(&text, "stanford.toml", None).unwrap();
/// assert_eq!(r.unknowns, Robot::stanford().unknowns);
/// let bad = text.replacen("limits = [0.3, 1.0]", "limits = [1.0, 0.3]", 1);
/// let e = file::parse(&bad, "stanford.toml", None).unwrap_err().to_string();
/// assert!(e.contains("frame '3': joint q3 has inverted limits [1, 0.3]"), "{e}");
/// assert!(e.starts_with("stanford.toml: line "), "{e}");
/// ```
pub fn parse_description(text: &str, origin: &str, dir: Option<&Path>) -> Result<Description> {
    let cx = Ctx { text, origin };
    let spec: FileSpec = toml::from_str(text).map_err(|e| cx.plain(e.to_string().trim_end()))?;
    let top = top_level(&cx, &spec)?;
    let contacts = contacts::contact_setup(&cx, &spec)?;
    if let Some(urdf) = &spec.urdf {
        let robot = imported(&cx, &spec, urdf, dir, &top)?;
        return Ok(Description {
            robot,
            visibility: top.visibility,
            contacts,
        });
    }
    check_chain_keys(&cx, &spec)?;
    let chain = frames_of(&cx, &spec)?;
    chain.check_unknowns_given(&cx, top.auto)?;
    let default_name = Path::new(origin)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("robot")
        .to_string();
    let mut robot = Robot {
        name: spec.name.clone().unwrap_or(default_name),
        frames: chain.frames,
        real: ParamTable::from_rows(chain.real),
        nominal: ParamTable::from_rows(chain.nominal),
        unknowns: chain.unknowns,
        limits: chain.limits,
        measurement: top.measurement,
        orientation_scale: top.orientation_scale,
        source: None,
        gravity: None,
    };
    if let Some((nominal, real)) = top.markers {
        robot.nominal.markers = nominal;
        robot.real.markers = real;
    }
    if top.auto {
        robot.unknowns = robot.choose_unknowns(&[]).map_err(|e| cx.plain(e))?;
        if robot.unknowns.is_empty() {
            return Err(cx.plain("no parameter of this chain is identifiable"));
        }
    }
    identifiable(&cx, robot, &chain.unknown_spans).map(|robot| Description {
        robot,
        visibility: top.visibility,
        contacts,
    })
}

/// The top-level keys of a description, checked: what is measured (with
/// the markers' offsets), the orientation weight, automatic unknowns, the
/// sensor's visibility region.
struct TopLevel {
    measurement: MeasurementKind,
    markers: Option<MarkerOffsets>,
    orientation_scale: f64,
    auto: bool,
    visibility: Option<Visibility>,
}

fn top_level(cx: &Ctx<'_>, spec: &FileSpec) -> Result<TopLevel> {
    let measurement = measurement_kind(cx, spec)?;
    let markers = marker_offsets(&cx, &spec.marker, measurement)?;
    let orientation_scale = match &spec.orientation_scale {
        None => crate::model::DEFAULT_ORIENTATION_SCALE,
        Some(s) if measurement != MeasurementKind::Pose => {
            return Err(cx.at(
                s.span(),
                "`orientation_scale` weighs orientation measurements: it needs `measurement = \"pose\"`",
            ));
        }
        Some(s) => {
            let v = *s.get_ref();
            if !(v.is_finite() && v > 0.0 && v <= MAX_ABS) {
                return Err(cx.at(
                    s.span(),
                    format!(
                        "orientation_scale = {}: must be a finite number in (0, {MAX_ABS:e}] (metres per radian)",
                        Compact(v)
                    ),
                ));
            }
            v
        }
    };
    let auto = match &spec.unknowns {
        None => false,
        Some(u) if u.get_ref() == "auto" => true,
        Some(u) => {
            return Err(cx.at(
                u.span(),
                format!(
                    "top-level `unknowns` must be \"auto\", not \"{}\" (list a frame's unknowns in its [[frame]] table)",
                    u.get_ref()
                ),
            ));
        }
    };
    let visibility = match &spec.visibility {
        None => None,
        Some(v) => {
            v.get_ref()
                .validate()
                .map_err(|m| cx.at(v.span(), format!("visibility: {m}")))?;
            Some(v.get_ref().clone())
        }
    };
    Ok(TopLevel {
        measurement,
        markers,
        orientation_scale,
        auto,
        visibility,
    })
}

/// The file's `measurement` key: one of the built-in sensors or a
/// registered one by its name ([`crate::measure::registered_kind`]); any
/// other value is refused at its place, naming those known.
fn measurement_kind(cx: &Ctx<'_>, spec: &FileSpec) -> Result<MeasurementKind> {
    // Parsing: this maps the key's spelling onto the enum (the one place a
    // file chooses a sensor by name; the pipelines then ask the sensor).
    let Some(m) = &spec.measurement else {
        return Ok(MeasurementKind::Point);
    };
    match m.get_ref().as_str() {
        "point" => Ok(MeasurementKind::Point),
        "pose" => Ok(MeasurementKind::Pose),
        "markers" => Ok(MeasurementKind::Markers(spec.marker.len())),
        name => crate::measure::registered_kind(name).ok_or_else(|| {
            let mut known = vec!["point", "pose", "markers"];
            known.extend(crate::measure::registered_names());
            cx.at(
                m.span(),
                format!(
                    "measurement = \"{name}\": unknown (known: {})",
                    known.join(", ")
                ),
            )
        }),
    }
}

/// A chain imported from a URDF (`urdf = …`, with `base`, `tip`, `lock`),
/// with the description's markers, name and orientation weight.
fn imported(
    cx: &Ctx<'_>,
    spec: &FileSpec,
    urdf: &Spanned<String>,
    dir: Option<&Path>,
    top: &TopLevel,
) -> Result<Robot> {
    let (measurement, markers, orientation_scale) =
        (top.measurement, &top.markers, top.orientation_scale);
    if !spec.frame.is_empty() {
        return Err(cx.at(
            urdf.span(),
            "give either `urdf = …` or [[frame]] tables, not both",
        ));
    }
    let path = match dir {
        Some(d) => d.join(urdf.get_ref()),
        None => Path::new(urdf.get_ref()).to_path_buf(),
    };
    let opts = super::urdf::UrdfOptions {
        base: spec.base.as_ref().map(|t| t.get_ref().clone()),
        tip: spec.tip.as_ref().map(|t| t.get_ref().clone()),
        lock: spec
            .lock
            .as_ref()
            .map(|l| l.get_ref().iter().map(|(k, v)| (k.clone(), *v)).collect())
            .unwrap_or_default(),
        measurement: if markers.is_some() {
            MeasurementKind::Point
        } else {
            measurement
        },
        ..super::urdf::UrdfOptions::default()
    };
    let mut r = super::urdf::load(&path, &opts).map_err(|e| cx.at(urdf.span(), e))?;
    if let Some((nominal, real)) = &markers {
        r = r.with_markers(nominal).map_err(|e| cx.plain(e))?;
        r.real.markers.clone_from(real);
    }
    if let Some(n) = spec.name.clone() {
        r.name = n;
    }
    r.orientation_scale = orientation_scale;
    Ok(r)
}

/// A description without `urdf = …`: no import keys, and 1 to
/// [`MAX_FRAMES`] frames.
fn check_chain_keys(cx: &Ctx<'_>, spec: &FileSpec) -> Result<()> {
    if let Some(t) = &spec.tip {
        return Err(cx.at(t.span(), "`tip` is only for `urdf = …` imports"));
    }
    if let Some(t) = &spec.base {
        return Err(cx.at(t.span(), "`base` is only for `urdf = …` imports"));
    }
    if let Some(t) = &spec.lock {
        return Err(cx.at(t.span(), "`lock` is only for `urdf = …` imports"));
    }
    if spec.frame.is_empty() {
        return Err(cx.plain(
            "no frames: describe the chain with [[frame]] tables, or import one with `urdf = \"file.urdf\"`",
        ));
    }
    if spec.frame.len() > MAX_FRAMES {
        return Err(cx.plain(format!(
            "{} frames: at most {MAX_FRAMES} are supported",
            spec.frame.len()
        )));
    }

    Ok(())
}

/// The robot, validated, if its unknowns are identifiable; otherwise an
/// error pointing at the first unidentifiable unknown's list.
fn identifiable(
    cx: &Ctx<'_>,
    robot: Robot,
    unknown_spans: &[Option<Range<usize>>],
) -> Result<Robot> {
    robot.validate().map_err(|e| cx.plain(e))?;
    match robot.check_identifiable() {
        Ok(_) => Ok(robot),
        Err(Error::Unidentifiable { names, rank, p }) => {
            let first = names
                .first()
                .and_then(|n| robot.param_id(n).ok())
                .and_then(|id| unknown_spans[id.frame].clone());
            let msg = format!(
                "unknowns {} are not identifiable from {} measurements (numerical rank {rank} of {p} on generic configurations at the nominal parameters): remove them, or set `unknowns = \"auto\"`",
                names.join(", "),
                robot.measurement.name(),
            );
            Err(match first {
                Some(span) => cx.at(span, msg),
                None => cx.plain(msg),
            })
        }
        Err(e) => Err(cx.plain(e)),
    }
}

/// Nominal and real offsets of the markers (metres, last frame).
type MarkerOffsets = (Vec<[f64; 3]>, Vec<[f64; 3]>);

/// The nominal and real marker offsets of `[[marker]]` tables, for a
/// `measurement = "markers"` file (`None` otherwise); tables without that
/// measurement, or that measurement without tables, are errors.
fn marker_offsets(
    cx: &Ctx<'_>,
    specs: &[MarkerSpec],
    measurement: MeasurementKind,
) -> Result<Option<MarkerOffsets>> {
    if measurement.markers() == 0 {
        return match specs.first() {
            Some(m) => Err(cx.at(
                m.nominal.span(),
                "[[marker]] tables need `measurement = \"markers\"`",
            )),
            None => Ok(None),
        };
    }
    if specs.is_empty() {
        return Err(cx.plain(
            "`measurement = \"markers\"` needs one [[marker]] table per marker, with its offset `nominal = [x, y, z]` in the last frame (metres)",
        ));
    }
    let offset = |k: usize, v: &Spanned<Vec<f64>>| -> Result<[f64; 3]> {
        match v.get_ref().as_slice() {
            &[x, y, z] if [x, y, z].iter().all(|c| c.is_finite() && c.abs() <= MAX_ABS) => {
                Ok([x, y, z])
            }
            other => Err(cx.at(
                v.span(),
                format!(
                    "marker {}: the offset must be 3 finite numbers [x, y, z] (metres, |value| <= {MAX_ABS:e}), not {other:?}",
                    k + 1
                ),
            )),
        }
    };
    let mut nominal = Vec::with_capacity(specs.len());
    let mut real = Vec::with_capacity(specs.len());
    for (k, m) in specs.iter().enumerate() {
        let n = offset(k, &m.nominal)?;
        nominal.push(n);
        real.push(match &m.real {
            Some(r) => offset(k, r)?,
            None => n,
        });
    }
    Ok(Some((nominal, real)))
}
