//! Standard deviations of the split frames: the fit's covariance `C` of the
//! identified parameters `θ` carried through the split `f(θ)` (measurement
//! frame, tool, markers, joint origins, as numbers) by its Jacobian `D`,
//! `Cov f = D C Dᵀ`, with `D` by central differences.

use super::{CalibratedFrames, FramesError, decompose};
use crate::model::{ParamTable, Robot};
use nalgebra::Isometry3;

/// Standard deviations of a frame: of its translation (metres) and of a
/// small rotation about its own x, y and z axes (radians: the rotation
/// vector of `R̂ᵀ R`, which unlike rpy has no gimbal lock).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameSigma {
    /// σ of x, y, z.
    pub xyz: [f64; 3],
    /// σ of the rotation about x, y, z.
    pub rot: [f64; 3],
}

/// Standard deviations of every figure of [`CalibratedFrames`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FramesSigma {
    /// The measurement frame's.
    pub measurement: FrameSigma,
    /// The tool's.
    pub tool: FrameSigma,
    /// Each marker offset's (metres).
    pub markers: Vec<[f64; 3]>,
    /// Each joint origin's.
    pub joints: Vec<FrameSigma>,
    /// Each joint's zero offset (radians).
    pub offsets: Vec<f64>,
}

fn push_frame(out: &mut Vec<f64>, t: &Isometry3<f64>, reference: &Isometry3<f64>) {
    out.extend(t.translation.vector.iter());
    // The rotation relative to the estimate's, as a rotation vector in the
    // frame's own axes: smooth everywhere (rpy is not at pitch ±90°).
    out.extend(
        (reference.rotation.inverse() * t.rotation)
            .scaled_axis()
            .iter(),
    );
}

/// The split as one vector of figures, angles taken near `reference`'s.
fn figures(f: &CalibratedFrames, reference: &CalibratedFrames) -> Vec<f64> {
    let mut v = Vec::new();
    push_frame(&mut v, &f.measurement, &reference.measurement);
    push_frame(&mut v, &f.tool, &reference.tool);
    for m in &f.markers {
        v.extend(m.iter());
    }
    for (j, r) in f.joints.iter().zip(&reference.joints) {
        push_frame(&mut v, &j.calibrated, &r.calibrated);
        v.push(j.offset());
    }
    v
}

/// The standard deviations of the split of `robot` at `table`, whose
/// identified parameters ([`Robot::unknown_values`]) have covariance
/// `cov` (row-major, [`Robot::n_params`] square).
pub fn sigmas(
    robot: &Robot,
    table: &ParamTable,
    cov: &[Vec<f64>],
) -> Result<FramesSigma, FramesError> {
    let at = decompose(robot, table)?;
    let theta = robot.unknown_values(table);
    let p = theta.len();
    if cov.len() != p || cov.iter().any(|r| r.len() != p) {
        return Err(FramesError::NotTheSource(format!(
            "a covariance of {} rows for {p} parameters",
            cov.len()
        )));
    }
    // Steps of 1e-6 (metres or radians) on figures of unit size: the
    // truncation error is ~1e-12 and the rounding ~1e-10 of a derivative,
    // far below the 1e-3 relative precision a σ needs.
    let h = 1e-6;
    let mut columns = Vec::with_capacity(p);
    for i in 0..p {
        let side = |s: f64| -> Result<Vec<f64>, FramesError> {
            let mut t = theta.clone();
            t[i] += s * h;
            let f = decompose(robot, &robot.with_unknowns(table, &t))?;
            Ok(figures(&f, &at))
        };
        let (plus, minus) = (side(1.0)?, side(-1.0)?);
        // The split solves its gauge to ~1e-15, so a difference quotient
        // carries ~1e-9 of noise: a derivative below 1e-8 is that noise (a
        // figure the gauge holds fixed), and would add at most 1e-8 of a
        // parameter's σ. It is zero.
        columns.push(
            plus.iter()
                .zip(&minus)
                .map(|(a, b)| (a - b) / (2.0 * h))
                .map(|d| if d.abs() < 1e-8 { 0.0 } else { d })
                .collect::<Vec<f64>>(),
        );
    }
    let m = figures(&at, &at).len();
    let var: Vec<f64> = (0..m)
        .map(|r| {
            let mut s = 0.0;
            for a in 0..p {
                let da = columns[a][r];
                if da == 0.0 {
                    continue;
                }
                for b in 0..p {
                    s += da * cov[a][b] * columns[b][r];
                }
            }
            s.max(0.0).sqrt()
        })
        .collect();
    Ok(unflatten(&var, &at))
}

fn frame_sigma(v: &[f64]) -> FrameSigma {
    FrameSigma {
        xyz: [v[0], v[1], v[2]],
        rot: [v[3], v[4], v[5]],
    }
}

fn unflatten(v: &[f64], f: &CalibratedFrames) -> FramesSigma {
    let mut s = FramesSigma {
        measurement: frame_sigma(&v[0..6]),
        tool: frame_sigma(&v[6..12]),
        ..FramesSigma::default()
    };
    let mut at = 12;
    for _ in &f.markers {
        s.markers.push([v[at], v[at + 1], v[at + 2]]);
        at += 3;
    }
    for _ in &f.joints {
        s.joints.push(frame_sigma(&v[at..at + 6]));
        s.offsets.push(v[at + 6]);
        at += 7;
    }
    s
}
