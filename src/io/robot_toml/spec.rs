//! The description file's shape as read (serde's view of the TOML, with
//! spans), its limits, and the place of a byte offset in the text.

use crate::error::Error;
use crate::measure::Visibility;
use crate::model::Convention;
use serde::Deserialize;
use std::ops::Range;
use toml::Spanned;

/// Most frames a description may have.
pub const MAX_FRAMES: usize = 100;

/// Largest magnitude accepted for a parameter or limit (metres or radians;
/// degrees for `limits_deg`): larger values are typing errors, and would
/// overflow the kinematics.
pub const MAX_ABS: f64 = 1e6;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileSpec {
    pub(super) name: Option<String>,
    pub(super) measurement: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) marker: Vec<MarkerSpec>,
    pub(super) orientation_scale: Option<Spanned<f64>>,
    pub(super) visibility: Option<Spanned<Visibility>>,
    pub(super) unknowns: Option<Spanned<String>>,
    pub(super) urdf: Option<Spanned<String>>,
    pub(super) base: Option<Spanned<String>>,
    pub(super) tip: Option<Spanned<String>>,
    pub(super) lock: Option<Spanned<std::collections::BTreeMap<String, f64>>>,
    #[serde(default)]
    pub(super) frame: Vec<FrameSpec>,
    #[serde(default)]
    pub(super) distance: Vec<Spanned<DistanceSpec>>,
    #[serde(default)]
    pub(super) plane: Vec<Spanned<PlaneSpec>>,
}

/// `[[distance]]`: a known distance between two contact points, metres.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DistanceSpec {
    pub(super) a: String,
    pub(super) b: String,
    pub(super) metres: f64,
}

/// `[[plane]]`: a known plane `normal · x = offset` (base frame, metres).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PlaneSpec {
    pub(super) name: String,
    pub(super) normal: [f64; 3],
    pub(super) offset: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MarkerSpec {
    pub(super) nominal: Spanned<Vec<f64>>,
    pub(super) real: Option<Spanned<Vec<f64>>>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub(super) enum JointSpec {
    Revolute,
    Prismatic,
    Fixed,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FrameSpec {
    pub(super) label: Spanned<String>,
    pub(super) convention: Convention,
    pub(super) joint: JointSpec,
    pub(super) limits: Option<Spanned<Vec<f64>>>,
    pub(super) limits_deg: Option<Spanned<Vec<f64>>>,
    pub(super) real: Spanned<Vec<f64>>,
    pub(super) nominal: Spanned<Vec<f64>>,
    pub(super) unknowns: Option<Spanned<Vec<Spanned<String>>>>,
}

/// The text being parsed, for turning byte spans into places.
#[derive(Clone, Copy)]
pub(super) struct Ctx<'a> {
    pub(super) text: &'a str,
    pub(super) origin: &'a str,
}

impl Ctx<'_> {
    /// `line L, column C` of a byte offset (both 1-based).
    pub(super) fn place(&self, offset: usize) -> (usize, usize) {
        let before = self.text.get(..offset).unwrap_or(self.text);
        let line = before.matches('\n').count() + 1;
        let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        (line, col)
    }

    pub(super) fn at(&self, span: Range<usize>, msg: impl std::fmt::Display) -> Error {
        let (line, col) = self.place(span.start);
        Error::Parse {
            path: self.origin.to_string(),
            message: format!("line {line}, column {col}: {msg}"),
        }
    }

    pub(super) fn plain(&self, msg: impl std::fmt::Display) -> Error {
        Error::Parse {
            path: self.origin.to_string(),
            message: msg.to_string(),
        }
    }
}
