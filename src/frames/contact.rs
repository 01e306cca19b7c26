//! The calibrated robot of a contact fit ([`crate::identify::contact`]) in
//! the user's terms: the split of [`super::decompose`] with the fitted tool
//! offset folded into the tool, so that the frames file's `point` is the
//! ball centre on the chain's tip link, and a `contacts` block with the
//! fitted points and planes.
//!
//! A contact fit's points and planes live in the model's base frame, which
//! is the measurement frame of the split (the parent of
//! `measurement_frame`): a row's tool point is `M · T_tip(q) · c`, with `M`
//! the measurement frame, `T_tip(q)` the calibrated URDF's placement of the
//! tip link in its base link and `c` the `point` on the tip link.

use super::report::{ContactPlaneBlock, ContactPointBlock, ContactsBlock, FitBlock, FramesReport};
use super::uncertainty::sigmas;
use super::{CalibratedFrames, FramesError, decompose};
use crate::data::NamedDistance;
use crate::identify::contact::ContactFit;
use crate::measure::ToolRecord;
use crate::model::{ParamTable, Robot};
use nalgebra::{Point3, Translation3, Vector3};

/// The split of a contact fit's robot with the tool moved to the tool
/// point (the ball centre), its report with standard deviations when the
/// fit has a covariance, and the `contacts` block. `None` for a robot not
/// imported from a URDF.
pub fn contact_frames(
    fit: &ContactFit,
    distances: &[NamedDistance],
    block: FitBlock,
) -> Result<Option<(CalibratedFrames, FramesReport)>, FramesError> {
    let robot = &fit.robot;
    let Some(src) = robot.source.as_ref() else {
        return Ok(None);
    };
    let mut f = decompose(robot, &fit.table)?;
    f.tool *= Translation3::from(Vector3::from(fit.tool_offset));
    let n_kin = robot.n_unknowns();
    let sigma = match &fit.covariance {
        Some(cov) => {
            let block_of = |n: usize| -> Vec<Vec<f64>> {
                cov.iter().take(n).map(|r| r[..n].to_vec()).collect()
            };
            let mut s = sigmas(robot, &fit.table, &block_of(n_kin))?;
            s.tool.xyz =
                tool_point_sigma(robot, &fit.table, &fit.tool_offset, &block_of(n_kin + 3))?;
            Some(s)
        }
        None => None,
    };
    // What a contact sensor records of the tool: its tool point
    // (`ContactSensor::tool_record`, the trait's default for a sensor
    // without orientation).
    let mut report = FramesReport::new(src, ToolRecord::Point, &f, sigma.as_ref(), Some(block));
    report.contacts = Some(contacts_block(fit, distances, n_kin));
    Ok(Some((f, report)))
}

/// The block of fitted points and planes; a point's σ from the fit's
/// standard deviations (its three own unknowns follow the robot's and the
/// tool offset's).
fn contacts_block(fit: &ContactFit, distances: &[NamedDistance], n_kin: usize) -> ContactsBlock {
    let first = n_kin + crate::measure::contact::TOOL_OFFSET_PARAMS;
    let points = fit
        .points
        .iter()
        .zip(&fit.point_positions)
        .enumerate()
        .map(|(g, (name, xyz))| ContactPointBlock {
            name: name.clone(),
            xyz: *xyz,
            sigma_xyz_mm: fit
                .std
                .as_ref()
                .map(|s| std::array::from_fn(|i| 1e3 * s[first + 3 * g + i])),
        })
        .collect();
    ContactsBlock {
        frame: "measurement".into(),
        tool_offset_end_frame: fit.tool_offset,
        points,
        planes: fit
            .planes
            .iter()
            .map(|p| ContactPlaneBlock {
                name: p.name.clone(),
                known: p.known,
                normal: p.normal,
                offset: p.offset_m,
            })
            .collect(),
        distances: distances.to_vec(),
    }
}

/// σ (metres) of the tool point on the tip link, `T(θ) · o`, from the
/// covariance `cov` of the robot's unknowns `θ` followed by the tool
/// offset `o`: `D C Dᵀ` with `D` by central differences in `θ` (the split
/// is not linear in it) and exactly `R_T` in `o`.
fn tool_point_sigma(
    robot: &Robot,
    table: &ParamTable,
    offset: &[f64; 3],
    cov: &[Vec<f64>],
) -> Result<[f64; 3], FramesError> {
    let theta = robot.unknown_values(table);
    let at = |t: &[f64]| -> Result<Vector3<f64>, FramesError> {
        let f = decompose(robot, &robot.with_unknowns(table, t))?;
        Ok((f.tool * Point3::from(Vector3::from(*offset))).coords)
    };
    // Steps of 1e-6 (metres or radians), as the split's own σ take them.
    let h = 1e-6;
    let mut columns: Vec<Vector3<f64>> = Vec::with_capacity(theta.len() + 3);
    for i in 0..theta.len() {
        let (mut plus, mut minus) = (theta.clone(), theta.clone());
        plus[i] += h;
        minus[i] -= h;
        columns.push((at(&plus)? - at(&minus)?) / (2.0 * h));
    }
    let rot = decompose(robot, table)?.tool.rotation;
    for k in 0..3 {
        columns.push(rot * Vector3::ith(k, 1.0));
    }
    Ok(std::array::from_fn(|r| {
        let mut s = 0.0;
        for (a, ca) in columns.iter().enumerate() {
            for (b, cb) in columns.iter().enumerate() {
                s += ca[r] * cov[a][b] * cb[r];
            }
        }
        s.max(0.0).sqrt()
    }))
}
