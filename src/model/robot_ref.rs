//! Which robot to load, as one typed value: a built-in name or a
//! description file, whether full poses are measured, and the chain of a
//! URDF tree ([`ChainChoice`]). The command line builds one from `--robot`
//! and the chain options once, [`crate::io`] loads it; design files record one (as a name and a
//! structured chain) and give it back.
//!
//! The text form `NAME[:pose|:SENSOR][#base=B;tip=T;lock=J:V,…;frames=F;kinematics=K;marker=L@X,Y,Z…]` is this
//! value's serialisation, read by [`RobotRef::parse`] and written by its
//! [`std::fmt::Display`]: a loaded robot's [`crate::model::Robot::name`], and
//! the `robot` of design files written before the chain was stored apart.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::Path;

/// Which chain of a URDF tree to take, and the frames to mount it with.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ChainChoice {
    /// The base link (default: the URDF's root).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub base: Option<String>,
    /// The tip link (required on a tree).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tip: Option<String>,
    /// Joints made fixed at a value (radians or metres).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub lock: Vec<(String, f64)>,
    /// A frames file ([`crate::io::frames_file`]): the measurement frame and
    /// tool (or markers) to mount the chain with.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frames: Option<String>,
    /// A kinematics file ([`crate::io::kinematics_yaml`]: Universal Robots'
    /// `default_kinematics.yaml` or per-joint origins) whose joint origins
    /// replace the URDF's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kinematics: Option<String>,
    /// Markers measured on the chain's tip, each a link (the tip's) and an
    /// offset in it (metres): the sensor the poses are chosen and the data
    /// fitted for. One marker makes a one-marker sensor (its offset
    /// unknown, `4R + 2P + 3` unknowns), several a `K`-marker sensor.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub markers: Vec<MarkerChoice>,
}

/// A marker on a link: `LINK@X,Y,Z`, the offset in metres in the link's frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MarkerChoice {
    /// The link the marker is fixed to (the chain's tip).
    pub link: String,
    /// Its position in that link's frame (metres).
    pub offset: [f64; 3],
}

impl MarkerChoice {
    /// Parses `LINK@X,Y,Z` (metres); errors name the text and what is wrong.
    pub fn parse(text: &str) -> Result<MarkerChoice> {
        let bad = |what: &str| Error::Invalid(format!("marker '{text}': {what}"));
        let (link, xyz) = text.split_once('@').ok_or_else(|| {
            bad("expected LINK@X,Y,Z (the link's name, then the offset in metres)")
        })?;
        if link.trim().is_empty() {
            return Err(bad("no link before '@'"));
        }
        let v: Vec<&str> = xyz.split(',').map(str::trim).collect();
        if v.len() != 3 {
            return Err(bad(&format!(
                "{} coordinates after '@', expected 3 (X,Y,Z in metres)",
                v.len()
            )));
        }
        let mut offset = [0.0; 3];
        for (o, t) in offset.iter_mut().zip(&v) {
            *o = t
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(&format!("'{t}' is not a finite number")))?;
        }
        Ok(MarkerChoice {
            link: link.trim().to_string(),
            offset,
        })
    }
}

impl fmt::Display for MarkerChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [x, y, z] = self.offset;
        write!(f, "{}@{x},{y},{z}", self.link)
    }
}

impl ChainChoice {
    /// Whether nothing is chosen.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.base.is_none()
            && self.tip.is_none()
            && self.lock.is_empty()
            && self.frames.is_none()
            && self.kinematics.is_none()
            && self.markers.is_empty()
    }

    /// The `#…` fragment of the text form (empty when nothing is chosen).
    #[must_use]
    pub fn fragment(&self) -> String {
        let mut parts = Vec::new();
        if let Some(b) = &self.base {
            parts.push(format!("base={b}"));
        }
        if let Some(t) = &self.tip {
            parts.push(format!("tip={t}"));
        }
        if !self.lock.is_empty() {
            let l: Vec<String> = self.lock.iter().map(|(n, v)| format!("{n}:{v}")).collect();
            parts.push(format!("lock={}", l.join(",")));
        }
        if let Some(f) = &self.frames {
            parts.push(format!("frames={f}"));
        }
        if let Some(k) = &self.kinematics {
            parts.push(format!("kinematics={k}"));
        }
        parts.extend(self.markers.iter().map(|m| format!("marker={m}")));
        if parts.is_empty() {
            String::new()
        } else {
            format!("#{}", parts.join(";"))
        }
    }

    /// Parses a list of held joints, `JOINT=VALUE,…` or `JOINT:VALUE,…`;
    /// errors name the item.
    pub fn parse_lock(text: &str) -> Result<Vec<(String, f64)>> {
        text.split(',')
            .filter(|s| !s.trim().is_empty())
            .map(|item| {
                let bad = |what: &str| Error::Invalid(format!("lock {item}: {what}"));
                let (n, v) = item
                    .split_once('=')
                    .or_else(|| item.split_once(':'))
                    .ok_or_else(|| bad("expected JOINT=VALUE (radians or metres)"))?;
                let v: f64 = v
                    .trim()
                    .parse()
                    .map_err(|_| bad(&format!("'{}' is not a number", v.trim())))?;
                if !v.is_finite() {
                    return Err(bad("not a finite number"));
                }
                Ok((n.trim().to_string(), v))
            })
            .collect()
    }

    /// Parses the `#…` fragment's text (without the `#`).
    fn parse_fragment(frag: &str) -> Result<ChainChoice> {
        let mut c = ChainChoice::default();
        for part in frag.split(';').filter(|p| !p.is_empty()) {
            match part.split_once('=') {
                Some(("base", v)) => c.base = Some(v.to_string()),
                Some(("tip", v)) => c.tip = Some(v.to_string()),
                Some(("lock", v)) => c.lock = ChainChoice::parse_lock(v)?,
                Some(("frames", v)) => c.frames = Some(v.to_string()),
                Some(("kinematics", v)) => c.kinematics = Some(v.to_string()),
                Some(("marker", v)) => c.markers.push(MarkerChoice::parse(v)?),
                _ => {
                    return Err(Error::Invalid(format!(
                        "robot name: unknown chain choice '{part}' after '#' (expected base=LINK, tip=LINK, lock=JOINT:VALUE,…, frames=FILE, kinematics=FILE or marker=LINK@X,Y,Z)"
                    )));
                }
            }
        }
        Ok(c)
    }
}

/// A robot to load: a built-in name or a `.toml`/`.urdf` path, the
/// measurement kind asked for, and the chain of a URDF tree.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RobotRef {
    /// A built-in robot's name or a description file's path, as given.
    pub name: String,
    /// Full poses asked for (the `:pose` suffix).
    pub pose: bool,
    /// A registered sensor asked for by its name (the `:NAME` suffix, e.g.
    /// `ur5:gauge`): resolved against `crate::measure::registered` when
    /// the robot is loaded, which refuses a name no sensor registers.
    pub sensor: Option<String>,
    /// The chain of a URDF tree.
    pub chain: ChainChoice,
}

impl RobotRef {
    /// Reads the text form (see the module documentation). A `:pose`
    /// suffix, or a `:NAME` suffix that is a lower-case word (a registered
    /// sensor's name, checked when loaded), is taken from the name unless a
    /// file of that exact name exists.
    pub fn parse(text: &str) -> Result<Self> {
        let (head, chain) = match text.rsplit_once('#') {
            Some((h, f)) if f.contains('=') => (h, ChainChoice::parse_fragment(f)?),
            _ => (text, ChainChoice::default()),
        };
        let suffix = head
            .rsplit_once(':')
            .filter(|(n, w)| !n.is_empty() && is_word(w) && !Path::new(head).exists());
        let (name, pose, sensor) = match suffix {
            Some((n, "pose")) => (n, true, None),
            Some((n, w)) => (n, false, Some(w.to_string())),
            None => (head, false, None),
        };
        Ok(Self {
            name: name.to_string(),
            pose,
            sensor,
            chain,
        })
    }

    /// The description file, if the name is a path with an extension.
    #[must_use]
    pub fn path(&self) -> &Path {
        Path::new(&self.name)
    }

    /// The file's lower-case extension (`urdf`, `toml`), if any.
    #[must_use]
    pub fn extension(&self) -> Option<String> {
        self.path()
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
    }

    /// Whether the robot is a `.urdf` file.
    #[must_use]
    pub fn is_urdf(&self) -> bool {
        self.extension().as_deref() == Some("urdf")
    }

    /// The name with its `:pose` suffix, without the chain: what a built-in
    /// robot is looked up by.
    #[must_use]
    pub fn head(&self) -> String {
        if self.pose {
            format!("{}:pose", self.name)
        } else {
            self.name.clone()
        }
    }
}

/// Whether `w` can name a sensor after `:`: a lower-case ASCII word
/// (letters, digits, `_`), starting with a letter.
fn is_word(w: &str) -> bool {
    w.starts_with(|c: char| c.is_ascii_lowercase())
        && w.chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
}

impl fmt::Display for RobotRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sensor = self
            .sensor
            .as_ref()
            .map_or(String::new(), |s| format!(":{s}"));
        write!(f, "{}{sensor}{}", self.head(), self.chain.fragment())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The text form round-trips through parse and display, and a `:pose`
    /// suffix and a fragment are both read.
    #[test]
    fn text_form_round_trips() {
        let t = "arm.urdf:pose#base=torso;tip=tool;lock=lift:0.1,head:-0.5;frames=cal.yaml;marker=tool@0.1,-0.02,0.05";
        let r = RobotRef::parse(t).unwrap();
        assert_eq!(r.name, "arm.urdf");
        assert!(r.pose);
        assert_eq!(r.chain.base.as_deref(), Some("torso"));
        assert_eq!(r.chain.tip.as_deref(), Some("tool"));
        assert_eq!(
            r.chain.lock,
            vec![("lift".to_string(), 0.1), ("head".to_string(), -0.5)]
        );
        assert_eq!(r.chain.frames.as_deref(), Some("cal.yaml"));
        assert_eq!(
            r.chain.markers,
            vec![MarkerChoice {
                link: "tool".into(),
                offset: [0.1, -0.02, 0.05]
            }]
        );
        assert_eq!(r.to_string(), t);
        assert_eq!(RobotRef::parse("puma560").unwrap().to_string(), "puma560");
        // Any word: the sensor's name is checked when the robot is loaded.
        let h = RobotRef::parse("arm.urdf:gauge_2#tip=tool").unwrap();
        assert_eq!((h.name.as_str(), h.pose), ("arm.urdf", false));
        assert_eq!(h.sensor.as_deref(), Some("gauge_2"));
        assert_eq!(h.to_string(), "arm.urdf:gauge_2#tip=tool");
        // Not a word after ':': part of the name.
        assert_eq!(RobotRef::parse("a:b/c.toml").unwrap().sensor, None);
        assert_eq!(RobotRef::parse("ur5:Pose").unwrap().name, "ur5:Pose");
        assert!(RobotRef::parse("a.urdf#colour=red").is_err());
        assert!(ChainChoice::parse_lock("j=abc").is_err());
        assert!(ChainChoice::parse_lock("j=inf").is_err());
    }
}
