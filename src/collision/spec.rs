//! What a collision filter checks, as a pool spec stores it: the URDF, the
//! chain's joints and locks, the SRDF, the obstacles (parsed from their
//! text form) and the clearance.

use serde::{Deserialize, Serialize};

/// An obstacle in the base link's frame (metres).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Obstacle {
    /// An axis-aligned box: centre and full sizes.
    Box {
        /// Centre.
        center: [f64; 3],
        /// Full sizes along x, y, z (> 0).
        size: [f64; 3],
    },
}

impl Obstacle {
    /// Parses `box:cx,cy,cz,sx,sy,sz` (centre and full sizes, metres).
    pub fn parse(text: &str) -> Result<Obstacle, String> {
        let Some(rest) = text.strip_prefix("box:") else {
            return Err(format!(
                "obstacle '{text}': expected box:cx,cy,cz,sx,sy,sz (centre and full sizes in metres, base frame)"
            ));
        };
        let v: Vec<f64> = rest
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| format!("obstacle '{text}': {e}"))?;
        if v.len() != 6 {
            return Err(format!(
                "obstacle '{text}': {} numbers, expected 6 (cx,cy,cz,sx,sy,sz)",
                v.len()
            ));
        }
        if let Some(x) = v.iter().find(|x| !x.is_finite()) {
            return Err(format!("obstacle '{text}': {x} is not finite"));
        }
        if let Some(s) = v[3..].iter().find(|s| **s <= 0.0) {
            return Err(format!("obstacle '{text}': size {s} must be > 0"));
        }
        Ok(Obstacle::Box {
            center: [v[0], v[1], v[2]],
            size: [v[3], v[4], v[5]],
        })
    }
}

/// The rule that finds link pairs touching by design when no SRDF lists
/// them: the pairs in contact in at least `fraction` of `samples`
/// configurations drawn uniformly within the chain's joint limits (from
/// `seed`; the other joints at their rest values) are not checked — the
/// "always in collision" rule of MoveIt's setup assistant, at its default
/// threshold of 95 %.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AlwaysTouching {
    /// Configurations drawn.
    pub samples: usize,
    /// The least fraction of them in which a pair touches to be skipped.
    pub fraction: f64,
    /// The draws' seed.
    pub seed: u64,
}

impl Default for AlwaysTouching {
    /// 1,000 configurations, 95 %, seed 0.
    fn default() -> Self {
        Self {
            samples: 1000,
            fraction: 0.95,
            seed: 0,
        }
    }
}

/// A link pair left unchecked because it touches in nearly every sampled
/// configuration.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TouchingPair {
    /// The first link.
    pub link: String,
    /// The other link.
    pub other: String,
    /// The fraction of the sampled configurations in which they touch.
    pub fraction: f64,
}

/// What a collision filter checks, as stored in a pool spec.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CollisionSpec {
    /// The URDF file.
    pub urdf: String,
    /// The URDF's text as the robot was imported from it, so that the file
    /// is read once per process; read from `urdf` when absent (a pool spec
    /// loaded from a design file).
    #[serde(skip)]
    pub text: Option<std::sync::Arc<str>>,
    /// The chain's moving joints, in the order of a configuration's values.
    pub joints: Vec<String>,
    /// Joints held at a value (`--lock`).
    #[serde(default)]
    pub lock: Vec<(String, f64)>,
    /// The frame of obstacles: the chain's base link (default: the root).
    #[serde(default)]
    pub base: Option<String>,
    /// Check the links against each other.
    #[serde(default)]
    pub self_collision: bool,
    /// SRDF whose `disable_collisions` pairs are not checked.
    #[serde(default)]
    pub srdf: Option<String>,
    /// Leave unchecked the link pairs that touch in nearly every
    /// configuration ([`AlwaysTouching`]): for a URDF without an SRDF.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub always_touching: Option<AlwaysTouching>,
    /// Directories searched for `package://` meshes.
    #[serde(default)]
    pub package_dirs: Vec<String>,
    /// Boxes in the base frame.
    #[serde(default)]
    pub obstacles: Vec<Obstacle>,
    /// A floor: the half-space `z < floor` of the base frame.
    #[serde(default)]
    pub floor: Option<f64>,
    /// Least distance kept between checked geometries (and to obstacles),
    /// metres: a configuration closer than this counts as a contact. 0:
    /// touching only.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub clearance: f64,
}

#[allow(clippy::trivially_copy_pass_by_ref)]
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obstacles_parse_and_refuse_bad_numbers() {
        assert_eq!(
            Obstacle::parse("box:0.5,0,0.1,0.2,0.2,0.2").unwrap(),
            Obstacle::Box {
                center: [0.5, 0.0, 0.1],
                size: [0.2, 0.2, 0.2]
            }
        );
        for (bad, why) in [
            ("sphere:1", "expected box"),
            ("box:1,2,3", "3 numbers"),
            ("box:0,0,0,1,1,-1", "must be > 0"),
            ("box:0,0,0,1,1,0", "must be > 0"),
            ("box:0,0,x,1,1,1", "invalid float"),
            ("box:0,0,inf,1,1,1", "not finite"),
        ] {
            let e = Obstacle::parse(bad).unwrap_err();
            assert!(e.contains(why) && e.contains(bad), "{bad}: {e}");
        }
    }
}
