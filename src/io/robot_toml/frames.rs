//! The chain of `[[frame]]` tables read into frames, both parameter
//! tables' rows, joint limits and listed unknowns, each value checked with
//! its line and column.

use super::spec::{Ctx, FileSpec, FrameSpec, JointSpec, MAX_ABS};
use crate::error::{Compact, Result};
use crate::model::{Convention, Frame, JointKind, ParamId, Symbol};
use std::ops::Range;
use toml::Spanned;

/// The chain of `[[frame]]` tables: frames, both tables' rows, joint
/// limits, the unknowns listed and where each frame listed them.
pub(super) struct FrameTables {
    pub(super) frames: Vec<Frame>,
    pub(super) real: Vec<[f64; 5]>,
    pub(super) nominal: Vec<[f64; 5]>,
    pub(super) limits: Vec<[f64; 2]>,
    pub(super) unknowns: Vec<ParamId>,
    /// Where each frame's unknowns were listed, to point at unidentifiable ones.
    pub(super) unknown_spans: Vec<Option<Range<usize>>>,
}

pub(super) fn frames_of(cx: &Ctx<'_>, spec: &FileSpec) -> Result<FrameTables> {
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
    pub(super) fn check_unknowns_given(&self, cx: &Ctx<'_>, auto: bool) -> Result<()> {
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

/// A parameter row: 5 values, or 4 for a DH frame (β = 0), all finite.
pub(super) fn row(
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

pub(super) fn joint_limits(
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
