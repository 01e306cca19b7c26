//! A robot's consistency checked (frames, limits, tables, unknowns), and a
//! joint vector checked against it.

use super::{Convention, JointKind, ParamId, Robot, Symbol};
use crate::error::{Error, Result};

impl Robot {
    /// Checks internal consistency: unique non-empty frame labels, joints
    /// numbered 0..dof once each, prismatic only on driven frames, finite
    /// parameters, valid limits, no β unknown on a DH frame, unknowns sorted
    /// and naming existing frames.
    pub fn validate(&self) -> Result<()> {
        if !(self.orientation_scale.is_finite() && self.orientation_scale > 0.0) {
            return Err(Error::Invalid(format!(
                "orientation_scale = {}: must be a finite number > 0 (metres per radian)",
                crate::error::Compact(self.orientation_scale)
            )));
        }
        self.validate_frames()?;
        self.validate_limits()?;
        self.validate_tables()?;
        self.validate_unknowns()
    }

    /// Labels unique and well formed, prismatic only on driven frames,
    /// joints numbered 0..dof once each.
    fn validate_frames(&self) -> Result<()> {
        let mut seen = vec![false; self.dof()];
        for (i, f) in self.frames.iter().enumerate() {
            if f.label.is_empty() || f.label.chars().any(|c| c.is_whitespace() || c == ',') {
                return Err(Error::Invalid(format!(
                    "frame {i}: label '{}' must be non-empty, without spaces or commas",
                    f.label
                )));
            }
            if self.frames[..i].iter().any(|g| g.label == f.label) {
                return Err(Error::Invalid(format!(
                    "frame {}: the label is used by two frames",
                    f.label
                )));
            }
            if f.joint.is_none() && f.joint_kind == JointKind::Prismatic {
                return Err(Error::Invalid(format!(
                    "frame {}: a fixed frame cannot be prismatic",
                    f.label
                )));
            }
        }
        for f in &self.frames {
            if let Some(j) = f.joint {
                if j >= seen.len() || seen[j] {
                    return Err(Error::Invalid(format!(
                        "frame {}: joint index {j} is out of range or used twice",
                        f.label
                    )));
                }
                seen[j] = true;
            }
        }
        if let Some(j) = seen.iter().position(|s| !s) {
            return Err(Error::Invalid(format!("joint q{} drives no frame", j + 1)));
        }
        Ok(())
    }

    /// Every joint's limits finite, ordered and not empty.
    fn validate_limits(&self) -> Result<()> {
        for (j, &[lo, hi]) in self.limits.iter().enumerate() {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(Error::InvalidLimits {
                    joint: j + 1,
                    lo,
                    hi,
                });
            }
            if lo == hi {
                let frame = self
                    .frames
                    .iter()
                    .find(|f| f.joint == Some(j))
                    .map_or("?", |f| f.label.as_str());
                return Err(Error::Invalid(format!(
                    "joint q{} (frame {frame}) has an empty range [{}, {}]: a joint that never moves leaves its frame's unknowns unidentifiable; give it a range, or make the frame fixed",
                    j + 1,
                    crate::error::Compact(lo),
                    crate::error::Compact(hi)
                )));
            }
        }
        Ok(())
    }

    /// Both tables: a row per frame, finite parameters, the sensor's
    /// number of finite marker offsets.
    fn validate_tables(&self) -> Result<()> {
        for table in [&self.real, &self.nominal] {
            if table.rows.len() != self.frames.len() {
                return Err(Error::Invalid(format!(
                    "parameter table has {} rows for {} frames",
                    table.rows.len(),
                    self.frames.len()
                )));
            }
            for (fi, row) in table.rows.iter().enumerate() {
                for s in Symbol::ALL {
                    let used = !(s == Symbol::Beta && self.frames[fi].convention == Convention::Dh);
                    if used && !row[s.column()].is_finite() {
                        return Err(Error::NonFiniteParameter {
                            name: self.param_name(ParamId {
                                frame: fi,
                                symbol: s,
                            }),
                            value: row[s.column()],
                        });
                    }
                }
            }
        }
        for (which, table) in [("real", &self.real), ("nominal", &self.nominal)] {
            let k = self.measurement.markers();
            if table.markers.len() != k {
                return Err(Error::Invalid(format!(
                    "the {which} table has {} marker offsets for a sensor of {k} markers",
                    table.markers.len()
                )));
            }
            if let Some(i) = table
                .markers
                .iter()
                .position(|o| o.iter().any(|v| !v.is_finite()))
            {
                return Err(Error::Invalid(format!(
                    "{which} marker {}: the offset {:?} is not finite",
                    i + 1,
                    table.markers[i]
                )));
            }
        }
        Ok(())
    }

    /// Unknowns present, sorted, unique, naming existing frames and
    /// parameters their frames have.
    fn validate_unknowns(&self) -> Result<()> {
        if self.unknowns.is_empty() {
            return Err(Error::Invalid("the robot has no unknown parameters".into()));
        }
        for w in self.unknowns.windows(2) {
            if w[0] >= w[1] {
                return Err(Error::Invalid(
                    "unknowns must be unique and frame-major".into(),
                ));
            }
        }
        for &u in &self.unknowns {
            if u.frame >= self.frames.len() {
                return Err(Error::Invalid(format!(
                    "unknown parameter {:?} refers to frame {} of {}",
                    u.symbol,
                    u.frame,
                    self.frames.len()
                )));
            }
            if u.symbol == Symbol::C && !self.is_compliant_frame(u.frame) {
                return Err(Error::Invalid(format!(
                    "{} is not a parameter: a compliance needs a revolute joint and the robot's gravity model",
                    self.param_name(u)
                )));
            }
            if u.symbol == Symbol::Beta && self.frames[u.frame].convention == Convention::Dh {
                return Err(Error::Invalid(format!(
                    "{} is not a parameter: frame {} is DH",
                    self.param_name(u),
                    self.frames[u.frame].label
                )));
            }
        }
        Ok(())
    }

    /// Validates a joint vector: length and finiteness (limits are not enforced:
    /// kinematics is defined everywhere).
    pub fn check_q(&self, q: &[f64]) -> Result<()> {
        if q.len() != self.dof() {
            return Err(Error::JointCount {
                expected: self.dof(),
                got: q.len(),
            });
        }
        if let Some((j, &v)) = q.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(Error::NonFiniteAngle {
                joint: j + 1,
                value: v,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;

    #[test]
    fn inverted_limits_are_rejected() {
        let mut r = Robot::puma560();
        r.limits[2] = [1.0, -1.0];
        assert!(matches!(
            r.validate(),
            Err(Error::InvalidLimits { joint: 3, .. })
        ));
    }
}
