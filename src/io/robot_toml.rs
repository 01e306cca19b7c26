//! Robot description files (TOML): frames, real and nominal parameter
//! tables, unknowns, joint limits, the measurement and an optional sensor
//! visibility region.
//!
//! ```toml
//! name = "puma560"            # optional; default: the file name
//! measurement = "point"       # "point" (3 rows per pose), "pose" (6 rows) or "markers" (3 per marker)
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

use super::Description;
use crate::error::{Compact, Error, Result};
use crate::measure::Visibility;
use crate::model::{
    Convention, Frame, JointKind, MeasurementKind, ParamId, ParamTable, Robot, Symbol,
};
use serde::{Deserialize, Serialize};
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

/// Most frames a description may have.
pub const MAX_FRAMES: usize = 100;

/// Largest magnitude accepted for a parameter or limit (metres or radians;
/// degrees for `limits_deg`): larger values are typing errors, and would
/// overflow the kinematics.
pub const MAX_ABS: f64 = 1e6;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSpec {
    name: Option<String>,
    measurement: Option<MeasurementSpec>,
    #[serde(default)]
    marker: Vec<MarkerSpec>,
    orientation_scale: Option<Spanned<f64>>,
    visibility: Option<Spanned<Visibility>>,
    unknowns: Option<Spanned<String>>,
    urdf: Option<Spanned<String>>,
    base: Option<Spanned<String>>,
    tip: Option<Spanned<String>>,
    lock: Option<Spanned<std::collections::BTreeMap<String, f64>>>,
    #[serde(default)]
    frame: Vec<FrameSpec>,
    #[serde(default)]
    distance: Vec<Spanned<DistanceSpec>>,
    #[serde(default)]
    plane: Vec<Spanned<PlaneSpec>>,
}

/// `[[distance]]`: a known distance between two contact points, metres.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DistanceSpec {
    a: String,
    b: String,
    metres: f64,
}

/// `[[plane]]`: a known plane `normal · x = offset` (base frame, metres).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlaneSpec {
    name: String,
    normal: [f64; 3],
    offset: f64,
}

/// The `[[distance]]` and `[[plane]]` tables, checked: a distance between
/// two different points, finite and > 0; a plane with a finite, non-zero
/// normal and a finite offset (each error at its table's line).
fn contact_setup(cx: &Ctx<'_>, spec: &FileSpec) -> Result<crate::io::ContactSetup> {
    let mut setup = crate::io::ContactSetup::default();
    for d in &spec.distance {
        let v = d.get_ref();
        if v.a == v.b || !(v.metres.is_finite() && v.metres > 0.0) {
            return Err(cx.at(
                d.span(),
                format!(
                    "[[distance]] {},{}={}: a distance needs two different points and a finite length > 0 (metres)",
                    v.a, v.b, v.metres
                ),
            ));
        }
        setup
            .distances
            .push(crate::identify::contact::NamedDistance {
                a: v.a.clone(),
                b: v.b.clone(),
                metres: v.metres,
            });
    }
    for p in &spec.plane {
        let v = p.get_ref();
        let n2: f64 = v.normal.iter().map(|c| c * c).sum();
        if !(n2.is_finite() && n2 > 0.0 && v.offset.is_finite()) {
            return Err(cx.at(
                p.span(),
                format!(
                    "[[plane]] '{}': a plane needs a finite, non-zero normal and a finite offset (metres)",
                    v.name
                ),
            ));
        }
        setup.planes.push(crate::identify::contact::NamedPlane {
            name: v.name.clone(),
            normal: v.normal,
            offset: v.offset,
        });
    }
    Ok(setup)
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum MeasurementSpec {
    Point,
    Pose,
    Markers,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MarkerSpec {
    nominal: Spanned<Vec<f64>>,
    real: Option<Spanned<Vec<f64>>>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum JointSpec {
    Revolute,
    Prismatic,
    Fixed,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FrameSpec {
    label: Spanned<String>,
    convention: Convention,
    joint: JointSpec,
    limits: Option<Spanned<Vec<f64>>>,
    limits_deg: Option<Spanned<Vec<f64>>>,
    real: Spanned<Vec<f64>>,
    nominal: Spanned<Vec<f64>>,
    unknowns: Option<Spanned<Vec<Spanned<String>>>>,
}

/// The text being parsed, for turning byte spans into places.
#[derive(Clone, Copy)]
struct Ctx<'a> {
    text: &'a str,
    origin: &'a str,
}

impl Ctx<'_> {
    /// `line L, column C` of a byte offset (both 1-based).
    fn place(&self, offset: usize) -> (usize, usize) {
        let before = self.text.get(..offset).unwrap_or(self.text);
        let line = before.matches('\n').count() + 1;
        let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        (line, col)
    }

    fn at(&self, span: Range<usize>, msg: impl std::fmt::Display) -> Error {
        let (line, col) = self.place(span.start);
        Error::Parse {
            path: self.origin.to_string(),
            message: format!("line {line}, column {col}: {msg}"),
        }
    }

    fn plain(&self, msg: impl std::fmt::Display) -> Error {
        Error::Parse {
            path: self.origin.to_string(),
            message: msg.to_string(),
        }
    }
}

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
    let contacts = contact_setup(&cx, &spec)?;
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
    let measurement = match spec.measurement {
        None | Some(MeasurementSpec::Point) => MeasurementKind::Point,
        Some(MeasurementSpec::Pose) => MeasurementKind::Pose,
        Some(MeasurementSpec::Markers) => MeasurementKind::Markers(spec.marker.len()),
    };
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

/// The chain of `[[frame]]` tables: frames, both tables' rows, joint
/// limits, the unknowns listed and where each frame listed them.
struct FrameTables {
    frames: Vec<Frame>,
    real: Vec<[f64; 5]>,
    nominal: Vec<[f64; 5]>,
    limits: Vec<[f64; 2]>,
    unknowns: Vec<ParamId>,
    /// Where each frame's unknowns were listed, to point at unidentifiable ones.
    unknown_spans: Vec<Option<Range<usize>>>,
}

fn frames_of(cx: &Ctx<'_>, spec: &FileSpec) -> Result<FrameTables> {
    let n = spec.frame.len();
    let mut t = FrameTables {
        frames: Vec::with_capacity(n),
        real: Vec::with_capacity(n),
        nominal: Vec::with_capacity(n),
        limits: Vec::new(),
        unknowns: Vec::new(),
        unknown_spans: Vec::new(),
    };
    for (i, f) in spec.frame.iter().enumerate() {
        t.push(cx, spec, i, f)?;
    }
    t.unknowns.sort();
    Ok(t)
}

impl FrameTables {
    /// Adds frame `i` of the file, checking its label, rows, joint and
    /// unknowns.
    fn push(&mut self, cx: &Ctx<'_>, spec: &FileSpec, i: usize, f: &FrameSpec) -> Result<()> {
        let (limits, unknowns) = (&mut self.limits, &mut self.unknowns);
        let label = f.label.get_ref();
        if label.is_empty() || label.chars().any(|c| c.is_whitespace() || c == ',') {
            return Err(cx.at(
                f.label.span(),
                format!("frame label '{label}' must be non-empty, without spaces or commas"),
            ));
        }
        if let Some(g) = spec.frame[..i].iter().find(|g| g.label.get_ref() == label) {
            let (line, _) = cx.place(g.label.span().start);
            return Err(cx.at(
                f.label.span(),
                format!("duplicate frame label '{label}' (first used on line {line})"),
            ));
        }
        let real_row = row(&cx, label, "real", &f.real, f.convention)?;
        let nominal_row = row(&cx, label, "nominal", &f.nominal, f.convention)?;
        let joint_no = limits.len() + 1;
        let (joint, kind) = match f.joint {
            JointSpec::Fixed => {
                if let Some(l) = f.limits.as_ref().or(f.limits_deg.as_ref()) {
                    return Err(cx.at(
                        l.span(),
                        format!("frame '{label}' is fixed: it has no joint limits"),
                    ));
                }
                (None, JointKind::Revolute)
            }
            JointSpec::Revolute | JointSpec::Prismatic => {
                let kind = if f.joint == JointSpec::Prismatic {
                    JointKind::Prismatic
                } else {
                    JointKind::Revolute
                };
                limits.push(joint_limits(&cx, label, joint_no, kind, f)?);
                (Some(joint_no - 1), kind)
            }
        };
        self.frames.push(Frame {
            label: label.clone(),
            convention: f.convention,
            joint,
            joint_kind: kind,
        });
        self.real.push(real_row);
        self.nominal.push(nominal_row);
        self.unknown_spans
            .push(f.unknowns.as_ref().map(|u| u.span()));
        for s in f.unknowns.iter().flat_map(|u| u.get_ref()) {
            let symbol = Symbol::parse(s.get_ref()).ok_or_else(|| {
                    cx.at(
                        s.span(),
                        format!(
                            "frame '{label}': unknown parameter symbol '{}' (expected gamma, alpha, a, d or beta)",
                            s.get_ref()
                        ),
                    )
                })?;
            if symbol == Symbol::Beta && f.convention == Convention::Dh {
                return Err(cx.at(
                    s.span(),
                    format!("frame '{label}' is a DH frame: it has no beta"),
                ));
            }
            let id = ParamId { frame: i, symbol };
            if unknowns.contains(&id) {
                return Err(cx.at(
                    s.span(),
                    format!("frame '{label}': '{}' is listed twice", s.get_ref()),
                ));
            }
            unknowns.push(id);
        }
        Ok(())
    }

    /// Unknowns come either from every frame's list or from
    /// `unknowns = "auto"`, never both, never neither.
    fn check_unknowns_given(&self, cx: &Ctx<'_>, auto: bool) -> Result<()> {
        let (unknowns, unknown_spans) = (&self.unknowns, &self.unknown_spans);
        if auto {
            if let Some(span) = unknown_spans.iter().flatten().next() {
                return Err(cx.at(
                    span.clone(),
                    "`unknowns = \"auto\"` at the top level and a frame's own `unknowns` list: give one or the other",
                ));
            }
        } else if unknowns.is_empty() {
            return Err(cx.plain(
                "no unknowns: list each frame's unknown parameters (`unknowns = [\"gamma\", …]`) or set `unknowns = \"auto\"` at the top",
            ));
        }
        Ok(())
    }
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
                "unknowns {} are not identifiable from {} measurements (numerical rank {rank} of {p} on a random design of the {}-level lattice at the nominal parameters): remove them, or set `unknowns = \"auto\"`",
                names.join(", "),
                robot.measurement.name(),
                crate::observability::DESIGN_LEVELS,
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

/// A parameter row: 5 values, or 4 for a DH frame (β = 0), all finite.
fn row(
    cx: &Ctx<'_>,
    label: &str,
    which: &str,
    v: &Spanned<Vec<f64>>,
    conv: Convention,
) -> Result<[f64; 5]> {
    let vals = v.get_ref();
    let ok_len = vals.len() == 5 || (vals.len() == 4 && conv == Convention::Dh);
    if !ok_len {
        let want = match conv {
            Convention::Dh => "4 or 5 values [gamma, alpha, a, d(, beta)]",
            Convention::Hayati => "5 values [gamma, alpha, a, d, beta]",
        };
        return Err(cx.at(
            v.span(),
            format!(
                "frame '{label}': `{which}` has {} values, a {} frame needs {want}",
                vals.len(),
                match conv {
                    Convention::Dh => "DH",
                    Convention::Hayati => "Hayati",
                }
            ),
        ));
    }
    let mut r = [0.0; 5];
    for (k, &x) in vals.iter().enumerate() {
        if !x.is_finite() {
            return Err(cx.at(
                v.span(),
                format!(
                    "frame '{label}': {which} {} is not a finite number ({x})",
                    Symbol::ALL[k]
                ),
            ));
        }
        if x.abs() > MAX_ABS {
            return Err(cx.at(
                v.span(),
                format!(
                    "frame '{label}': {which} {} = {} is out of range (|value| <= {MAX_ABS:e})",
                    Symbol::ALL[k],
                    Compact(x)
                ),
            ));
        }
        r[k] = x;
    }
    Ok(r)
}

fn joint_limits(
    cx: &Ctx<'_>,
    label: &str,
    joint_no: usize,
    kind: JointKind,
    f: &FrameSpec,
) -> Result<[f64; 2]> {
    let (v, scale) = match (&f.limits, &f.limits_deg) {
        (Some(_), Some(d)) => {
            return Err(cx.at(
                d.span(),
                format!("frame '{label}': give `limits` or `limits_deg`, not both"),
            ));
        }
        (None, None) => {
            return Err(cx.at(
                f.label.span(),
                format!(
                    "frame '{label}': joint q{joint_no} needs `limits = [lo, hi]` ({}) or `limits_deg`",
                    match kind {
                        JointKind::Revolute => "radians",
                        JointKind::Prismatic => "metres",
                    }
                ),
            ));
        }
        (Some(l), None) => (l, 1.0),
        (None, Some(d)) => {
            if kind == JointKind::Prismatic {
                return Err(cx.at(
                    d.span(),
                    format!(
                        "frame '{label}': joint q{joint_no} is prismatic: give `limits` in metres, not `limits_deg`"
                    ),
                ));
            }
            (d, std::f64::consts::PI / 180.0)
        }
    };
    let vals = v.get_ref();
    if vals.len() != 2 {
        return Err(cx.at(
            v.span(),
            format!(
                "frame '{label}': joint q{joint_no} limits need 2 values [lo, hi], got {}",
                vals.len()
            ),
        ));
    }
    let (lo, hi) = (vals[0], vals[1]);
    if !(lo.is_finite() && hi.is_finite()) || lo.abs() > MAX_ABS || hi.abs() > MAX_ABS {
        return Err(cx.at(
            v.span(),
            format!(
                "frame '{label}': joint q{joint_no} limits [{}, {}] are not finite numbers within ±{MAX_ABS:e}",
                Compact(lo),
                Compact(hi)
            ),
        ));
    }
    if lo > hi {
        return Err(cx.at(
            v.span(),
            format!(
                "frame '{label}': joint q{joint_no} has inverted limits [{}, {}] (need lo <= hi)",
                Compact(lo),
                Compact(hi)
            ),
        ));
    }
    if lo == hi {
        return Err(cx.at(
            v.span(),
            format!(
                "frame '{label}': joint q{joint_no} has an empty range [{}, {}]: a joint that never moves leaves its frame's unknowns unidentifiable; give it a range, or make the frame fixed (`joint = \"fixed\"`) with the value in its table",
                Compact(lo),
                Compact(hi)
            ),
        ));
    }
    Ok([lo * scale, hi * scale])
}

/// Writes a robot as a description that [`parse`] reads back to the same
/// robot (tables bit for bit: numbers are written as the shortest decimals
/// that round-trip; limits in radians or metres). A DH frame's β is written
/// when finite (the paper's marker 10), omitted otherwise.
#[must_use]
pub fn to_toml(robot: &Robot) -> String {
    description_to_toml(robot, None)
}

/// As [`to_toml`], with a visibility region.
#[must_use]
pub fn description_to_toml(robot: &Robot, visibility: Option<&Visibility>) -> String {
    let num = |x: f64| format!("{x:?}");
    let list = |r: &[f64]| {
        let v: Vec<String> = r.iter().map(|&x| num(x)).collect();
        format!("[{}]", v.join(", "))
    };
    let mut s = String::new();
    s += "# activecal robot description (see activecal::io::robot_toml)\n";
    s += &format!("name = {:?}\n", robot.name);
    s += &format!("measurement = \"{}\"\n", robot.measurement.name());
    if robot.measurement == MeasurementKind::Pose {
        s += &format!("orientation_scale = {}\n", num(robot.orientation_scale));
    }
    for (n, r) in robot.nominal.markers.iter().zip(&robot.real.markers) {
        s += &format!("\n[[marker]]\nnominal = {}\nreal = {}\n", list(n), list(r));
    }
    for (i, f) in robot.frames.iter().enumerate() {
        s += "\n[[frame]]\n";
        s += &format!("label = {:?}\n", f.label);
        s += &format!(
            "convention = \"{}\"\n",
            match f.convention {
                Convention::Dh => "dh",
                Convention::Hayati => "hayati",
            }
        );
        let joint = match (f.joint, f.joint_kind) {
            (None, _) => "fixed",
            (Some(_), JointKind::Revolute) => "revolute",
            (Some(_), JointKind::Prismatic) => "prismatic",
        };
        s += &format!("joint = \"{joint}\"\n");
        if let Some(j) = f.joint {
            s += &format!("limits = {}\n", list(&robot.limits[j]));
        }
        for (name, t) in [("real", &robot.real), ("nominal", &robot.nominal)] {
            let r = &t.rows[i];
            let n = if f.convention == Convention::Dh && !r[4].is_finite() {
                4
            } else {
                5
            };
            s += &format!("{name} = {}\n", list(&r[..n]));
        }
        let syms: Vec<String> = robot
            .unknowns
            .iter()
            // A compliance belongs to the gravity model, not the description.
            .filter(|u| u.frame == i && u.symbol != Symbol::C)
            .map(|u| format!("\"{}\"", u.symbol))
            .collect();
        if !syms.is_empty() {
            s += &format!("unknowns = [{}]\n", syms.join(", "));
        }
    }
    if let Some(v) = visibility {
        #[derive(Serialize)]
        struct W<'a> {
            visibility: &'a Visibility,
        }
        if let Ok(t) = toml::to_string(&W { visibility: v }) {
            s += "\n";
            s += &t;
        }
    }
    s
}
