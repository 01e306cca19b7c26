//! Joint speed limits of a URDF robot (`<limit velocity="…">`), by joint
//! name, for planning the order a design is measured in. Kept apart from
//! the URDF importer: the kinematic model needs no speeds.

use crate::error::{Error, Result};

/// Speed limits of a chain's joints.
#[derive(Clone, Debug, PartialEq)]
pub struct JointSpeeds {
    /// Speed per moving joint of the chain, rad/s or m/s, in configuration
    /// order; `None` where the URDF gives none (absent, zero, not finite).
    pub speeds: Vec<Option<f64>>,
    /// The chain's joint names, in configuration order.
    pub joints: Vec<String>,
}

impl JointSpeeds {
    /// The speeds with `fallback` where the URDF gives none.
    #[must_use]
    pub fn or(&self, fallback: f64) -> Vec<f64> {
        self.speeds.iter().map(|v| v.unwrap_or(fallback)).collect()
    }
}

/// The speed limits of a URDF robot's chain, from the text it was imported
/// from ([`super::UrdfChain`]); `None` for a built-in robot or a
/// description file, which state no speeds.
pub fn joint_speeds(robot: &crate::model::Robot) -> Result<Option<JointSpeeds>> {
    let Some(chain) = super::UrdfChain::of(robot) else {
        return Ok(None);
    };
    Ok(Some(speeds_in(&chain.text, &chain.file, chain.joints)?))
}

/// The speeds of `joints` in URDF text (`origin` names it in errors).
pub fn speeds_in(text: &str, origin: &str, joints: Vec<String>) -> Result<JointSpeeds> {
    let urdf = urdf_rs::read_from_string(text).map_err(|e| Error::Parse {
        path: origin.to_string(),
        message: e.to_string(),
    })?;
    let speeds = joints
        .iter()
        .map(|name| {
            let j = urdf
                .joints
                .iter()
                .find(|j| &j.name == name)
                .ok_or_else(|| Error::Parse {
                    path: origin.to_string(),
                    message: format!("no joint '{name}'"),
                })?;
            let v = j.limit.velocity;
            Ok((v.is_finite() && v > 0.0).then_some(v))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(JointSpeeds { speeds, joints })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speeds_are_read_by_joint_name() {
        let text = r#"<robot name="r">
  <link name="a"/><link name="b"/><link name="c"/>
  <joint name="j1" type="revolute"><parent link="a"/><child link="b"/>
    <limit lower="-1" upper="1" effort="1" velocity="2.5"/></joint>
  <joint name="j2" type="revolute"><parent link="b"/><child link="c"/>
    <limit lower="-1" upper="1" effort="1" velocity="0"/></joint>
</robot>"#;
        let s = speeds_in(text, "r.urdf", vec!["j2".into(), "j1".into()]).unwrap();
        assert_eq!(s.speeds, vec![None, Some(2.5)]);
        assert_eq!(s.or(1.0), vec![1.0, 2.5]);
        let e = speeds_in(text, "r.urdf", vec!["j9".into()]).unwrap_err();
        assert!(e.to_string().contains("j9"), "{e}");
    }
}
