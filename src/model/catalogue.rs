//! The built-in arms beyond the paper's PUMA: a UR5 and a Stanford arm, and
//! the full-pose variants of all three (`Robot::builtin("ur5:pose")`).
//!
//! Both arms are seen by a sensor 2 m from the base, like the paper's
//! tracker 20 m from the PUMA: frame `a` is a fixed Hayati frame
//! `Rz(π/2) Tx(2 m)` (measurement z parallel to joint 1; a Hayati frame
//! needs the offset `a ≠ 0` to place the joint-1 axis). The measured point is
//! a target 0.1 m off the last joint axis (the `a` of the last joint frame;
//! on the axis, the last joint's offset would not be observable), and a fixed
//! Hayati identity frame `t` carries the tool orientation for full-pose
//! measurements.
//!
//! The "real" robots are the nominal ones with every unknown of the
//! full-pose variant perturbed by [`perturbation`] (at most 5 mm or 5 mrad).
//! The three extra full-pose unknowns (α of the last joint frame, γ and β of
//! `t`) rotate about axes through the measured point, so the point variant
//! sees the same real robot.

use super::{Convention, Frame, JointKind, MeasurementKind, ParamId, ParamTable, Robot, Symbol};
use std::f64::consts::FRAC_PI_2;

/// The deterministic perturbation added to parameter `(frame, symbol)` of a
/// built-in arm's nominal table to make its real one:
/// `1e-3 · (((7·frame + 3·column) mod 11) − 5)` (metres or radians; the
/// column is [`Symbol::column`]).
#[must_use]
pub fn perturbation(id: ParamId) -> f64 {
    1e-3 * (((7 * id.frame + 3 * id.symbol.column()) % 11) as f64 - 5.0)
}

/// `nominal` with [`perturbation`] added to each parameter in `ids`.
#[must_use]
pub fn perturbed(nominal: &ParamTable, ids: &[ParamId]) -> ParamTable {
    let mut t = nominal.clone();
    for &id in ids {
        t.set(id, nominal.get(id) + perturbation(id));
    }
    t
}

/// (label, convention, joint, kind, nominal row `[γ, α, a, d, β]`).
type FrameRow = (&'static str, Convention, Option<usize>, JointKind, [f64; 5]);

fn ids(frames: &[FrameRow], per_frame: &[(&str, &[Symbol])]) -> Vec<ParamId> {
    let mut v: Vec<ParamId> = per_frame
        .iter()
        .flat_map(|&(label, syms)| {
            let frame = frames
                .iter()
                .position(|f| f.0 == label)
                .expect("label of a built-in frame");
            syms.iter().map(move |&symbol| ParamId { frame, symbol })
        })
        .collect();
    v.sort();
    v
}

fn assemble(
    name: &str,
    frames: &[FrameRow],
    point_unknowns: Vec<ParamId>,
    pose_extra: Vec<ParamId>,
    limits: Vec<[f64; 2]>,
    m: MeasurementKind,
) -> Robot {
    let nominal = ParamTable::from_rows(frames.iter().map(|f| f.4).collect());
    let mut pose_unknowns = point_unknowns.clone();
    pose_unknowns.extend(pose_extra);
    pose_unknowns.sort();
    let real = perturbed(&nominal, &pose_unknowns);
    let (name, unknowns) = match m {
        MeasurementKind::Point => (name.to_string(), point_unknowns),
        MeasurementKind::Pose => (format!("{name}:pose"), pose_unknowns),
        MeasurementKind::Markers(_) | MeasurementKind::Registered(_) => {
            unreachable!("built-in robots measure points or poses")
        }
    };
    let r = Robot {
        name,
        frames: frames
            .iter()
            .map(|&(label, convention, joint, joint_kind, _)| Frame {
                label: label.to_string(),
                convention,
                joint,
                joint_kind,
            })
            .collect(),
        real,
        nominal,
        unknowns,
        limits,
        measurement: m,
        orientation_scale: super::DEFAULT_ORIENTATION_SCALE,
        source: None,
        gravity: None,
    };
    debug_assert!(r.validate().is_ok());
    r
}

fn deg(limits: &[[f64; 2]]) -> Vec<[f64; 2]> {
    limits
        .iter()
        .map(|&[lo, hi]| [lo.to_radians(), hi.to_radians()])
        .collect()
}

impl Robot {
    /// A Universal Robots UR5 measured at a point (27 unknowns); see
    /// [`ur5_with`].
    #[must_use]
    pub fn ur5() -> Robot {
        ur5_with(MeasurementKind::Point)
    }

    /// A Stanford arm measured at a point (25 unknowns); see
    /// [`stanford_with`].
    #[must_use]
    pub fn stanford() -> Robot {
        stanford_with(MeasurementKind::Point)
    }
}

/// A Universal Robots UR5 (6R; joints 2, 3 and 4 parallel).
///
/// Nominal numbers: Universal Robots' published DH table for the UR5
/// ("DH parameters for calculations of kinematics and dynamics", standard DH
/// `Rz(θ) Tz(d) Tx(a) Rx(α)`, the form of our DH frames): d1 = 0.089159,
/// a2 = −0.425, a3 = −0.39225, d4 = 0.10915, d5 = 0.09465, d6 = 0.0823 m;
/// α1 = π/2, α4 = π/2, α5 = −π/2, all other a, d, α zero. Frames 2 and 3 map
/// between parallel axes and are Hayati frames (d = 0, β = 0); UR's d2 = d3 =
/// 0, so the model is exactly UR's. Added here (module docs): the sensor
/// frame `a` 2 m from the base, the target offset a6 = 0.1 m, the tool frame
/// `t`.
///
/// Unknowns (point, 27 = 4·6 + 3): γ α a β of `a`, γ α a d of 1, γ α a β of
/// 2 and 3, γ α a d of 4 and 5, γ a d of 6. Full pose (30): also α_6 and γ β
/// of `t`.
///
/// Joint ranges (degrees) are working ranges chosen for calibration pools:
/// the datasheet allows ±360° on every joint, but a lattice over ±360°
/// repeats poses (its end values coincide modulo 360°). q1, q4, q5, q6 ∈
/// [−170, 170]; q2 ∈ [−180, 0] (upper arm above the mounting plane); q3 ∈
/// [−160, 160] (elbow clear of the upper arm).
#[must_use]
pub fn ur5_with(m: MeasurementKind) -> Robot {
    use Convention::{Dh, Hayati};
    use JointKind::Revolute as R;
    let frames: [FrameRow; 8] = [
        ("a", Hayati, None, R, [FRAC_PI_2, 0.0, 2.0, 0.0, 0.0]),
        ("1", Dh, Some(0), R, [0.0, FRAC_PI_2, 0.0, 0.089159, 0.0]),
        ("2", Hayati, Some(1), R, [0.0, 0.0, -0.425, 0.0, 0.0]),
        ("3", Hayati, Some(2), R, [0.0, 0.0, -0.39225, 0.0, 0.0]),
        ("4", Dh, Some(3), R, [0.0, FRAC_PI_2, 0.0, 0.10915, 0.0]),
        ("5", Dh, Some(4), R, [0.0, -FRAC_PI_2, 0.0, 0.09465, 0.0]),
        ("6", Dh, Some(5), R, [0.0, 0.0, 0.1, 0.0823, 0.0]),
        ("t", Hayati, None, R, [0.0; 5]),
    ];
    use Symbol::{A, Alpha, Beta, D, Gamma};
    let point = ids(
        &frames,
        &[
            ("a", &[Gamma, Alpha, A, Beta]),
            ("1", &[Gamma, Alpha, A, D]),
            ("2", &[Gamma, Alpha, A, Beta]),
            ("3", &[Gamma, Alpha, A, Beta]),
            ("4", &[Gamma, Alpha, A, D]),
            ("5", &[Gamma, Alpha, A, D]),
            ("6", &[Gamma, A, D]),
        ],
    );
    let extra = ids(&frames, &[("6", &[Alpha]), ("t", &[Gamma, Beta])]);
    let limits = deg(&[
        [-170.0, 170.0],
        [-180.0, 0.0],
        [-160.0, 160.0],
        [-170.0, 170.0],
        [-170.0, 170.0],
        [-170.0, 170.0],
    ]);
    assemble("ur5", &frames, point, extra, limits, m)
}

/// The Stanford (Scheinman) arm: RRPRRR, a prismatic boom (joint 3) and a
/// spherical wrist.
///
/// Nominal numbers: the standard-DH table of Paul, *Robot Manipulators*
/// (1981), also Spong, Hutchinson & Vidyasagar, *Robot Modeling and Control*
/// (Table 3.4), with the lengths of Stanford AI Memo 177 (Fig. 2.3) as
/// tabulated in Corke's Robotics Toolbox (`mdl_stanford`): d1 = 0.412 m,
/// α1 = −π/2; d2 = 0.154 m, α2 = π/2; joint 3 prismatic with θ3 = −π/2;
/// α4 = −π/2; α5 = π/2; d6 = 0.263 m; all a zero. Frame 3 maps between
/// coaxial axes (3 and 4) and is a Hayati frame. Added here (module docs):
/// the sensor frame `a`, the target offset a6 = 0.1 m, the tool frame `t`.
///
/// Unknowns (point, 25 = 4·5 + 2·1 + 3): γ α a β of `a`, γ α a d of 1 and
/// 2, α β of 3 (the direction of the boom's motion is set by frame 2, and
/// the boom axis's location does not matter, so a_3 would repeat a_2/d_2 and
/// γ_3 would repeat γ_4), γ α a d of 4 and 5 (d_4 is the boom's offset), γ a
/// d of 6. Full pose (28): also α_6 and γ β of `t`.
///
/// Ranges, chosen for calibration pools: q1, q4, q6 ∈ [−170°, 170°], q2, q5
/// ∈ [−90°, 90°], boom q3 ∈ [0.3, 1.0] m.
#[must_use]
pub fn stanford_with(m: MeasurementKind) -> Robot {
    use Convention::{Dh, Hayati};
    use JointKind::{Prismatic as P, Revolute as R};
    let frames: [FrameRow; 8] = [
        ("a", Hayati, None, R, [FRAC_PI_2, 0.0, 2.0, 0.0, 0.0]),
        ("1", Dh, Some(0), R, [0.0, -FRAC_PI_2, 0.0, 0.412, 0.0]),
        ("2", Dh, Some(1), R, [0.0, FRAC_PI_2, 0.0, 0.154, 0.0]),
        ("3", Hayati, Some(2), P, [-FRAC_PI_2, 0.0, 0.0, 0.0, 0.0]),
        ("4", Dh, Some(3), R, [0.0, -FRAC_PI_2, 0.0, 0.0, 0.0]),
        ("5", Dh, Some(4), R, [0.0, FRAC_PI_2, 0.0, 0.0, 0.0]),
        ("6", Dh, Some(5), R, [0.0, 0.0, 0.1, 0.263, 0.0]),
        ("t", Hayati, None, R, [0.0; 5]),
    ];
    use Symbol::{A, Alpha, Beta, D, Gamma};
    let point = ids(
        &frames,
        &[
            ("a", &[Gamma, Alpha, A, Beta]),
            ("1", &[Gamma, Alpha, A, D]),
            ("2", &[Gamma, Alpha, A, D]),
            ("3", &[Alpha, Beta]),
            ("4", &[Gamma, Alpha, A, D]),
            ("5", &[Gamma, Alpha, A, D]),
            ("6", &[Gamma, A, D]),
        ],
    );
    let extra = ids(&frames, &[("6", &[Alpha]), ("t", &[Gamma, Beta])]);
    let mut limits = deg(&[
        [-170.0, 170.0],
        [-90.0, 90.0],
        [0.0, 0.0],
        [-170.0, 170.0],
        [-90.0, 90.0],
        [-170.0, 170.0],
    ]);
    limits[2] = [0.3, 1.0];
    assemble("stanford", &frames, point, extra, limits, m)
}

/// The paper's PUMA 560 ([`Robot::puma560`], Tables I and II) measured in
/// full pose: frame 6 becomes a Hayati frame with β = 0 in both tables (the
/// same transform as the identity DH frame; the paper's β = 10 marker would
/// otherwise be read as a rotation), and the unknowns gain α_5, γ_6 and β_6
/// (30 = 4·6 + 6). Their real values equal the nominal ones (0): the paper
/// gives no tool orientation error.
#[must_use]
pub fn puma560_pose() -> Robot {
    let mut r = Robot::puma560();
    r.name = "puma560:pose".into();
    r.measurement = MeasurementKind::Pose;
    r.frames[7].convention = Convention::Hayati;
    r.real.rows[7][4] = 0.0;
    r.nominal.rows[7][4] = 0.0;
    r.unknowns.extend([
        ParamId {
            frame: 6,
            symbol: Symbol::Alpha,
        },
        ParamId {
            frame: 7,
            symbol: Symbol::Gamma,
        },
        ParamId {
            frame: 7,
            symbol: Symbol::Beta,
        },
    ]);
    r.unknowns.sort();
    debug_assert!(r.validate().is_ok());
    r
}
