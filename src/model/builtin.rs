//! The built-in robots by name, and the paper's PUMA 560 (Tables I and II)
//! itself; the other arms are in [`super::catalogue`].

use super::{
    Convention, DEFAULT_ORIENTATION_SCALE, Frame, JointKind, MeasurementKind, ParamId, ParamTable,
    Robot, Symbol, catalogue,
};
use crate::error::{Error, Result};
use std::f64::consts::PI;

/// Names of the built-in robots (point measurements; append `:pose` for the
/// full-pose variant, see [`Robot::builtin`]).
pub const BUILTIN: &[&str] = &["puma560", "ur5", "stanford"];

impl Robot {
    /// A built-in robot by name: `puma560` (or `puma`), `ur5`, `stanford`.
    /// A name with the suffix `:pose` (`ur5:pose`) gives the same robot with
    /// full-pose measurements and the three orientation unknowns more that
    /// they identify (see [`catalogue`]).
    pub fn builtin(name: &str) -> Result<Robot> {
        let (base, m) = match name.strip_suffix(":pose") {
            Some(b) => (b, MeasurementKind::Pose),
            None => (name, MeasurementKind::Point),
        };
        match (base, m) {
            ("puma560" | "puma", MeasurementKind::Point) => Ok(Robot::puma560()),
            ("puma560" | "puma", MeasurementKind::Pose) => Ok(catalogue::puma560_pose()),
            ("ur5", m) => Ok(catalogue::ur5_with(m)),
            ("stanford", m) => Ok(catalogue::stanford_with(m)),
            _ => Err(Error::UnknownRobot {
                name: name.to_string(),
                known: BUILTIN.join(", "),
            }),
        }
    }

    /// The PUMA 560 of Sun & Hollerbach §V-A: Tables I (real) and II
    /// (nominal), joint limits eq. (25), 27 unknowns.
    ///
    /// Frame `a` is a fixed Hayati frame from the measurement frame to the
    /// base (20 m away), frame 0 is joint 1 (DH), frame 1 joint 2 (Hayati),
    /// frames 2–5 joints 3–6 (DH), frame 6 the identity.
    #[must_use]
    pub fn puma560() -> Robot {
        use Convention::{Dh, Hayati};
        let frames: Vec<Frame> = [
            ("a", Hayati, None),
            ("0", Dh, Some(0)),
            ("1", Hayati, Some(1)),
            ("2", Dh, Some(2)),
            ("3", Dh, Some(3)),
            ("4", Dh, Some(4)),
            ("5", Dh, Some(5)),
            ("6", Dh, None),
        ]
        .into_iter()
        .map(|(l, c, j)| Frame {
            label: l.to_string(),
            convention: c,
            joint: j,
            joint_kind: JointKind::Revolute,
        })
        .collect();
        // Table I (β = 10 marks "no β" in the paper; kept for display, ignored for DH).
        let real = ParamTable::from_rows(vec![
            [PI / 2.0, PI / 100.0, 20.0, 0.0, PI / 100.0],
            [0.0, -PI / 2.0, 0.0, 0.6858, 10.0],
            [0.0, PI / 100.0, 0.4318, 0.0, PI / 100.0],
            [0.0, PI / 2.0, -0.0203, 0.1491, 10.0],
            [0.0, -PI / 2.0, 0.0, 0.4331, 10.0],
            [0.0, PI / 2.0, 0.0, 0.0, 10.0],
            [0.0, 0.0, 0.2, 0.1655, 10.0],
            [0.0, 0.0, 0.0, 0.0, 10.0],
        ]);
        // Table II.
        let nominal = ParamTable::from_rows(vec![
            [1.6360, 0.1572, 19.8820, 0.0, -0.0123],
            [-0.0367, -1.4524, 0.0603, 0.6713, 10.0],
            [-0.1455, -0.2622, 0.3411, 0.0, -0.1963],
            [0.0128, 1.6374, -0.1214, 0.0074, 10.0],
            [0.0024, -1.3948, -0.1029, 0.3002, 10.0],
            [0.1207, 1.6151, -0.0468, -0.0747, 10.0],
            [0.0938, 0.0, 0.1322, 0.3083, 10.0],
            [0.0, 0.0, 0.0, 0.0, 10.0],
        ]);
        use Symbol::{A, Alpha, Beta, D, Gamma};
        let per_frame: [&[Symbol]; 7] = [
            &[Gamma, Alpha, A, Beta],
            &[Gamma, Alpha, A, D],
            &[Gamma, Alpha, A, Beta],
            &[Gamma, Alpha, A, D],
            &[Gamma, Alpha, A, D],
            &[Gamma, Alpha, A, D],
            &[Gamma, A, D],
        ];
        let unknowns = per_frame
            .iter()
            .enumerate()
            .flat_map(|(f, syms)| {
                syms.iter().map(move |&s| ParamId {
                    frame: f,
                    symbol: s,
                })
            })
            .collect();
        let deg = PI / 180.0;
        let limits = [
            [-250.0, 70.0],
            [-110.0, 170.0],
            [-133.0, 133.0],
            [-100.0, 100.0],
            [-142.0, 142.0],
            [-176.0, 356.0],
        ]
        .iter()
        .map(|[lo, hi]| [lo * deg, hi * deg])
        .collect();
        Robot {
            name: "puma560".into(),
            frames,
            real,
            nominal,
            unknowns,
            limits,
            measurement: MeasurementKind::Point,
            orientation_scale: DEFAULT_ORIENTATION_SCALE,
            source: None,
            gravity: None,
        }
    }
}
