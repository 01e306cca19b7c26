//! Calibration without an instrument: contacts with fixed points and planes
//! ([`crate::measure::contact`]) and the distances known between points.
//!
//! * this file: known distances by name, the start of the points and
//!   planes (an unknown plane's chart about its rows' best-fit plane), the tool
//!   points a model predicts, and the figures of a model on contacts
//!   (consistency: the RMS distance of each row's predicted tool point to
//!   its point's mean; distance errors);
//! * [`fit`](mod@fit): the fit (identifiable unknowns, the gauge, a robust
//!   loss that names the rows it down-weights);
//! * [`predict`]: the true error the fit's covariance predicts for the
//!   tool point at random configurations (what held-out placements
//!   cannot see);
//! * [`worth`]: which weakly determined unknowns are worth estimating at
//!   the data's noise;
//! * [`lengths`]: known distances and plane offsets checked against the
//!   robot's reach;
//! * [`holdout`]: held out by placement (the part of a point's name before
//!   `/`): leave one placement out, and train on one;
//! * [`select`]: the pool of configurations at sockets a design chooses
//!   from (`crate::select::contact` chooses).

pub mod evaluate;
pub mod fit;
pub mod holdout;
pub mod lengths;
pub mod predict;
pub mod project;
pub mod select;
pub mod worth;

use crate::data::{ContactFile, NamedDistance};
pub use fit::{ContactFit, ContactSettings, PlaneEstimate, fit_contacts};
pub use holdout::{
    DistanceFigure, DownweightedRow, Figures, HoldoutFold, HoldoutMode, PlacementHoldout,
    PlaneFigure, PointFigure, RowDistance, holdout_by_placement, judge, placements, row_distances,
};

use crate::error::Error;
use crate::kinematics::Evaluator;
use crate::measure::contact::{ContactSensor, KnownDistance, Plane, PlaneKind, TOOL_OFFSET_PARAMS};
use crate::model::{ParamTable, Robot};
use nalgebra::Vector3;

/// The distances of `given` between points of `file`, as indices. With
/// `strict`, a distance naming a point the file does not have is an error
/// naming it; otherwise it is left out (a training subset without that
/// point). A distance that is not finite and positive, or between a point
/// and itself, is an error.
pub fn resolve_distances(
    file: &ContactFile,
    given: &[NamedDistance],
    strict: bool,
) -> crate::error::Result<Vec<KnownDistance>> {
    let mut out = Vec::new();
    for d in given {
        let label = format!("distance {},{}={}", d.a, d.b, d.metres);
        if !(d.metres.is_finite() && d.metres > 0.0) || d.a == d.b {
            return Err(Error::Invalid(format!(
                "{label}: a distance needs two different points and a finite length > 0 (metres)"
            )));
        }
        match (file.point_index(&d.a), file.point_index(&d.b)) {
            (Some(a), Some(b)) => out.push(KnownDistance {
                a,
                b,
                metres: d.metres,
            }),
            (ia, _) if strict => {
                let missing = if ia.is_none() { &d.a } else { &d.b };
                return Err(Error::Invalid(format!(
                    "{label}: {} has no point '{missing}' (its points: {})",
                    file.origin,
                    file.points.join(", ")
                )));
            }
            _ => {}
        }
    }
    Ok(out)
}

/// Refuses contacts with no known distance between two of their points:
/// nothing then fixes the scale, and a fit shrinks the arm (every joint
/// origin's offset to zero, the tool on a joint axis) until every contact
/// coincides — a "perfect" fit of any data (MUKCa's `panda_2` without its
/// distances: σ̂ = 0, every point at joint 2's origin). Planes do not fix it
/// either (the collapsed tool point lies on them).
pub fn check_scale(file: &ContactFile, known: &[KnownDistance]) -> crate::error::Result<()> {
    if known.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: no known distance between two of its points, so nothing fixes the scale: a fit would shrink the arm until every contact coincides; give the distance between two points it touches (e.g. the two sockets of a block)",
            file.origin
        )));
    }
    Ok(())
}

/// The placement of a point: its name before the first `/` (the whole name
/// without one).
#[must_use]
pub fn placement_of(point: &str) -> &str {
    point.split('/').next().unwrap_or(point)
}

/// The tool point `p + R o` of every row of `qs` for `robot` with `table`
/// and tool offset `offset` (end frame).
#[must_use]
pub fn tool_points(
    robot: &Robot,
    table: &ParamTable,
    offset: &[f64; 3],
    qs: &[Vec<f64>],
) -> Vec<Vector3<f64>> {
    let mut ev = Evaluator::new(robot, table);
    qs.iter()
        .map(|q| ContactSensor::tool_point(&ev.end_frame(q), offset))
        .collect()
}

/// The mean of `pts` over the rows of each of `n` groups.
#[must_use]
pub fn group_means(pts: &[Vector3<f64>], groups: &[usize], n: usize) -> Vec<Vector3<f64>> {
    let mut sum = vec![Vector3::zeros(); n];
    let mut count = vec![0usize; n];
    for (p, &g) in pts.iter().zip(groups) {
        sum[g] += p;
        count[g] += 1;
    }
    sum.iter()
        .zip(&count)
        .map(|(s, &c)| s / c.max(1) as f64)
        .collect()
}

/// Each row's distance (metres) from its group's mean.
#[must_use]
pub fn spreads(pts: &[Vector3<f64>], groups: &[usize], n: usize) -> Vec<f64> {
    let means = group_means(pts, groups, n);
    pts.iter()
        .zip(groups)
        .map(|(p, &g)| (p - means[g]).norm())
        .collect()
}

/// The root mean square of `v` (0 for none).
#[must_use]
pub fn rms(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// The own unknowns at the start: a zero tool offset, each point at the
/// mean of its rows' tool points predicted by `table`, and each unknown
/// plane at the chart centre of [`start_planes`] (`a = b = 0`) with the
/// offset of the plane through its rows' mean.
#[must_use]
pub fn start_own(robot: &Robot, table: &ParamTable, file: &ContactFile) -> Vec<f64> {
    let pts = tool_points(robot, table, &[0.0; 3], &file.qs);
    let n = file.points.len() + file.planes.len();
    let means = group_means(&pts, &file.groups, n);
    let mut own = vec![0.0; TOOL_OFFSET_PARAMS];
    for m in &means[..file.points.len()] {
        own.extend_from_slice(m.as_slice());
    }
    for (l, p) in start_planes(robot, table, file).iter().enumerate() {
        if let PlaneKind::Unknown { n0 } = p.kind {
            let d = Vector3::from(n0).dot(&means[file.points.len() + l]);
            own.extend_from_slice(&[0.0, 0.0, d]);
        }
    }
    own
}

/// The file's planes, each unknown one with its chart centred on the
/// normal of the plane that fits its rows' tool points (predicted by
/// `table`, no tool offset) best: the start of the fit.
#[must_use]
pub fn start_planes(robot: &Robot, table: &ParamTable, file: &ContactFile) -> Vec<Plane> {
    if file.planes.is_empty() {
        return Vec::new();
    }
    let pts = tool_points(robot, table, &[0.0; 3], &file.qs);
    let g0 = file.points.len();
    file.planes
        .iter()
        .enumerate()
        .map(|(l, p)| match p.kind {
            PlaneKind::Known { .. } => p.clone(),
            PlaneKind::Unknown { .. } => {
                let rows: Vec<Vector3<f64>> =
                    file.rows_of(g0 + l).iter().map(|&i| pts[i]).collect();
                let (n, _) = best_plane(&rows);
                Plane {
                    name: p.name.clone(),
                    kind: PlaneKind::Unknown { n0: n.into() },
                }
            }
        })
        .collect()
}

/// The plane `n · x = d` (unit `n`) nearest `pts` in the least-squares
/// sense: through their mean, `n` the direction of least spread.
#[must_use]
pub fn best_plane(pts: &[Vector3<f64>]) -> (Vector3<f64>, f64) {
    let mean = pts.iter().sum::<Vector3<f64>>() / pts.len().max(1) as f64;
    let mut cov = nalgebra::Matrix3::zeros();
    for p in pts {
        let d = p - mean;
        cov += d * d.transpose();
    }
    let eig = cov.symmetric_eigen();
    let k = eig.eigenvalues.imin();
    let n: Vector3<f64> = eig.eigenvectors.column(k).into();
    (n, n.dot(&mean))
}
