//! Choosing identifiable unknowns, and checking them, on generic
//! configurations of the robot.
//!
//! A frame's *candidate* unknowns are its four structural parameters: γ, α,
//! a, d for a DH frame and γ, α, a, β for a Hayati frame (a Hayati frame's d
//! is the paper's fixed 0, redundant with the d of the next DH frame along
//! the nearly parallel axes; a fixed Hayati tool frame at the end keeps its
//! d too). Some candidates are redundant with others — the
//! α of the last joint frame for point measurements, the location of a
//! prismatic axis, a tool frame's translations — and
//! [`Robot::choose_unknowns`] drops them: it walks the candidates in a
//! preference order and keeps each one whose Jacobian column is not in the
//! span of the columns kept before (a greedy column selection by
//! Gram–Schmidt). For a generic chain the result has the textbook size
//! ([`Robot::minimal_unknowns`]): `4R + 2P + 3` for points, `4R + 2P + 6`
//! for full poses.
//!
//! The columns come from generic configurations ([`generic_configurations`]:
//! each joint uniform over its range, a joint that turns all the way round
//! over one turn) at the nominal parameters, with a fixed seed, so the
//! choice is reproducible. Never from lattice levels, which on a joint whose
//! limits are ±2π coincide modulo 2π and hide a direction real data see.

use crate::blocks::Blocks;
use crate::blocks::jacobian_of;
use crate::error::{Error, Result};
use crate::linalg::eigen::symmetric_eigen;
use crate::linalg::gram::gram_of;
use crate::linalg::rank::{equilibrated, rank_of_eigenvalues};
use crate::model::{Convention, MeasurementKind, ParamId, ParamTable, Robot, Symbol};

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// A candidate is kept when the component of its unit-norm column orthogonal
/// to the kept columns has norm above this: `1/√MAX_CONDITION` (3.2e-7),
/// since a smaller component makes the smallest singular value of the
/// unit-column Jacobian smaller than that and the set fails the rank rule
/// every command shares (`linalg::rank`). On the built-in robots
/// (point and pose) dependent columns leave at most 4e-16 (rounding) and the
/// independent ones at least 0.09 (`tests/robots.rs` checks both), so the
/// threshold separates them by several orders of magnitude on each side.
pub const INDEPENDENCE_TOL: f64 = 3.162_277_660_168_379_5e-7;

/// Largest accepted condition number of the equilibrated information matrix
/// `D^-½ XᵀX D^-½` (`D = diag XᵀX`): the one rank rule of `select`, `bound`,
/// `score`, `gap` and `calibrate` (see [`identifiability`]).
pub const MAX_CONDITION: f64 = crate::linalg::rank::MAX_CONDITION;

/// Seed of the design [`Robot::choose_unknowns`] uses.
const CHOOSE_SEED: u64 = 0x5eed_0c00_5e00;
/// Seed of the design [`Robot::check_identifiable`] uses (a different design,
/// so the check does not merely repeat the choice).
const CHECK_SEED: u64 = 0x5eed_c4ec_0001;

/// Result of an identifiability check.
#[derive(Clone, Debug, Serialize)]
pub struct Identifiability {
    /// Numerical rank of the column-scaled stacked Jacobian, by the rule of
    /// `linalg::rank`.
    pub rank: usize,
    /// Number of unknowns.
    pub p: usize,
    /// Unknowns with a significant component in the numerical null space.
    pub unidentifiable: Vec<String>,
    /// Singular values of the column-scaled Jacobian, largest first.
    pub singular_values: Vec<f64>,
}

/// Numerical rank of a stacked Jacobian and the unknowns it cannot determine,
/// by the rank rule every command shares (`linalg::rank`).
///
/// Works on the normal equations of the column-scaled problem: `M = XᵀX`
/// (`O(rows·p²)` time, `O(p²)` memory — never a copy of `X`, let alone a
/// `rows × rows` matrix), equilibrated to `M̃ = D^-½ M D^-½ = X̃ᵀX̃` (`X̃`
/// with unit-norm columns; rank is scale-invariant, a tolerance is not). The
/// rank counts the eigenvalues `σ̃²` of `M̃` with
/// `σ̃² · MAX_CONDITION > σ̃_max²`; a zero column is unidentifiable outright.
/// An unknown is named when its entry in an eigenvector of the rejected
/// eigenvalues (the numerical null space) exceeds 1e-6 in magnitude.
#[must_use]
pub fn identifiability(robot: &Robot, x: &Blocks) -> Identifiability {
    let m = x.mat();
    let (rows, p) = (m.nrows(), m.ncols());
    let names = robot.parameter_names();
    let (scaled, _) = equilibrated(gram_of(m).as_ref());
    let Some((ev, v)) = symmetric_eigen(scaled.as_ref()) else {
        // Only a non-finite Jacobian gets here: nothing is determined.
        return Identifiability {
            rank: 0,
            p,
            unidentifiable: names,
            singular_values: vec![0.0; p.min(rows)],
        };
    };
    // Eigenvalues come nondecreasing: the largest rank of them pass.
    let rank = rank_of_eigenvalues(&ev, MAX_CONDITION);
    let mut flagged = vec![false; p];
    for k in 0..p - rank {
        for (c, f) in flagged.iter_mut().enumerate() {
            if v[(c, k)].abs() > 1e-6 {
                *f = true;
            }
        }
    }
    let unidentifiable = names
        .into_iter()
        .zip(flagged)
        .filter(|(_, f)| *f)
        .map(|(n, _)| n)
        .collect();
    Identifiability {
        rank,
        p,
        unidentifiable,
        singular_values: ev
            .iter()
            .rev()
            .take(p.min(rows))
            .map(|&l| l.max(0.0).sqrt())
            .collect(),
    }
}

/// Checks that every unknown is identifiable from `x`, or returns
/// [`Error::Unidentifiable`] naming the ones that are not.
pub fn require_identifiable(robot: &Robot, x: &Blocks) -> Result<Identifiability> {
    let id = identifiability(robot, x);
    if id.rank < id.p {
        return Err(Error::Unidentifiable {
            names: id.unidentifiable.clone(),
            rank: id.rank,
            p: id.p,
        });
    }
    Ok(id)
}

impl Robot {
    /// The structural candidate unknowns of every frame, frame-major: γ, α,
    /// a, d for DH frames, γ, α, a, β for Hayati frames — and all five
    /// (γ, α, a, d, β) for a fixed Hayati frame at the end of the chain (a
    /// tool frame, whose `d` has no later frame to repeat it: it carries the
    /// measured point's distance along the tool line).
    #[must_use]
    pub fn candidate_unknowns(&self) -> Vec<ParamId> {
        use Symbol::{A, Alpha, Beta, D, Gamma};
        let mut v = Vec::with_capacity(5 * self.frames.len());
        let n = self.frames.len();
        for (frame, f) in self.frames.iter().enumerate() {
            let syms: &[Symbol] = match f.convention {
                Convention::Dh => &[Gamma, Alpha, A, D],
                Convention::Hayati if frame + 1 == n && f.joint.is_none() => {
                    &[Gamma, Alpha, A, D, Beta]
                }
                Convention::Hayati => &[Gamma, Alpha, A, Beta],
            };
            v.extend(syms.iter().map(|&symbol| ParamId { frame, symbol }));
        }
        v
    }

    /// The number of independent parameters of a generic serial chain with
    /// this robot's joints and measurement: `4R + 2P + 3` for point
    /// measurements, `4R + 2P + 6` for full poses (R revolute, P prismatic
    /// joints; Everett, Driels & Mooring 1987, less 3 for a point), and for
    /// `K` markers `4R + 2P + 3K`: each marker's offset places it freely in
    /// the last joint frame, so the offsets absorb the whole tool frame. Special
    /// geometries (a measured point on the last joint axis, coaxial joints)
    /// have fewer.
    #[must_use]
    pub fn minimal_unknowns(&self) -> usize {
        let p = self.frames.iter().filter(|f| f.is_prismatic()).count();
        let r = self.dof().saturating_sub(p);
        let sensor = crate::measure::sensor_for(self);
        match self.measurement.markers() {
            // The offsets place each marker freely in the last joint frame:
            // they absorb the whole tool frame, translation and rotation.
            0 => 4 * r + 2 * p + sensor.observed_dof(),
            k => 4 * r + 2 * p + 3 * k,
        }
    }

    /// A maximal identifiable set of unknowns: `preferred` first (in the given
    /// order), then the [candidates](Robot::candidate_unknowns) frame-major,
    /// each kept if its Jacobian column is independent of those kept before
    /// (see the module documentation). Returned frame-major, as
    /// [`Robot::unknowns`] must be. Errors if the kinematics is not finite on
    /// the design (parameters too large).
    pub fn choose_unknowns(&self, preferred: &[ParamId]) -> Result<Vec<ParamId>> {
        let walk = self.independence(preferred)?;
        let mut kept: Vec<(ParamId, f64)> = walk
            .into_iter()
            .filter(|&(_, r)| r > INDEPENDENCE_TOL)
            .collect();
        kept.sort_by_key(|&(u, _)| u);
        // A pivot above the tolerance is necessary for the rank rule, not
        // sufficient: near a gimbal of a tool frame's angles a pivot of 1e-6
        // can still leave the set's condition beyond it. Drop the weakest
        // flagged unknown until the set passes the check every command makes.
        while !kept.is_empty() {
            let mut probe = self.clone();
            probe.unknowns = kept.iter().map(|&(u, _)| u).collect();
            let id = match probe.check_identifiable() {
                Ok(_) => break,
                Err(Error::Unidentifiable { names, .. }) => names,
                Err(e) => return Err(e),
            };
            let weakest = kept
                .iter()
                .enumerate()
                .filter(|(_, (u, _))| id.contains(&self.param_name(*u)))
                .min_by(|a, b| a.1.1.total_cmp(&b.1.1))
                .map(|(k, _)| k);
            match weakest {
                Some(k) => {
                    kept.remove(k);
                }
                None => break,
            }
        }
        Ok(kept.into_iter().map(|(u, _)| u).collect())
    }

    /// The greedy walk of [`Robot::choose_unknowns`]: every parameter it
    /// considers, in walk order, with the norm of the part of its unit-norm
    /// column orthogonal to the columns kept before it (0 for a zero
    /// column). Those above [`INDEPENDENCE_TOL`] are kept.
    pub fn independence(&self, preferred: &[ParamId]) -> Result<Vec<(ParamId, f64)>> {
        self.check_shape()?;
        let mut order: Vec<ParamId> = Vec::new();
        for &u in preferred.iter().chain(&self.candidate_unknowns()) {
            if u.frame < self.frames.len() && !order.contains(&u) {
                order.push(u);
            }
        }
        if order.is_empty() {
            return Ok(Vec::new());
        }
        let mut all = order.clone();
        all.sort();
        let mut probe = self.clone();
        probe.unknowns = all.clone();
        let n = (2 * all.len()).max(40);
        let x = design_jacobian(&probe, &self.nominal, n, CHOOSE_SEED)?;
        let m = x.mat();
        let rows = m.nrows();
        let col = |k: usize| -> Vec<f64> { (0..rows).map(|r| m[(r, k)]).collect() };
        let norms: Vec<f64> = (0..all.len())
            .map(|k| col(k).iter().map(|v| v * v).sum::<f64>().sqrt())
            .collect();
        let scale = norms.iter().cloned().fold(0.0, f64::max);
        let mut basis: Vec<Vec<f64>> = Vec::new();
        // A marker sensor's own offsets come first: always unknown, they take
        // the tool translation that the robot's candidates would repeat.
        for k in all.len()..m.ncols() {
            let mut v = col(k);
            for _ in 0..2 {
                for b in &basis {
                    let d: f64 = b.iter().zip(&v).map(|(x, y)| x * y).sum();
                    v.iter_mut().zip(b).for_each(|(y, x)| *y -= d * x);
                }
            }
            let r = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if r > 0.0 {
                v.iter_mut().for_each(|x| *x /= r);
                basis.push(v);
            }
        }
        let mut out = Vec::with_capacity(order.len());
        for u in order {
            let k = all.binary_search(&u).expect("all holds every candidate");
            // A column that is zero up to rounding (α of the last frame for a
            // point, say) is unidentifiable outright.
            if norms[k].is_nan() || norms[k] <= 1e-12 * scale {
                out.push((u, 0.0));
                continue;
            }
            let mut v: Vec<f64> = col(k).iter().map(|x| x / norms[k]).collect();
            // Two passes of modified Gram–Schmidt ("twice is enough").
            for _ in 0..2 {
                for b in &basis {
                    let d: f64 = b.iter().zip(&v).map(|(x, y)| x * y).sum();
                    v.iter_mut().zip(b).for_each(|(y, x)| *y -= d * x);
                }
            }
            let r = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if r > INDEPENDENCE_TOL {
                v.iter_mut().for_each(|x| *x /= r);
                basis.push(v);
            }
            out.push((u, r));
        }
        Ok(out)
    }

    /// Checks numerically that every unknown is identifiable: the stacked
    /// Jacobian (nominal parameters) of `max(40, 2p)` [generic
    /// configurations](generic_configurations) with a fixed seed, has full column rank
    /// ([`require_identifiable`]).
    pub fn check_identifiable(&self) -> Result<Identifiability> {
        self.check_shape()?;
        if self.unknowns.is_empty() {
            return Err(Error::Invalid("the robot has no unknown parameters".into()));
        }
        if let Some(u) = self.unknowns.iter().find(|u| u.frame >= self.frames.len()) {
            return Err(Error::Invalid(format!(
                "an unknown refers to frame {} of {}",
                u.frame,
                self.frames.len()
            )));
        }
        let n = (2 * self.n_unknowns()).max(40);
        let x = design_jacobian(self, &self.nominal, n, CHECK_SEED)?;
        require_identifiable(self, &x)
    }

    /// A copy measuring `m`, with its unknowns re-chosen by
    /// [`Robot::choose_unknowns`] (the current unknowns preferred) and
    /// checked. For full poses the last frame must be able to carry the tool's
    /// orientation: a fixed DH last frame becomes a Hayati frame with β = 0
    /// (the same transform), and a chain ending in a driven frame gets a
    /// fixed Hayati identity frame `tool`.
    ///
    /// ```
    /// use activecal::model::{MeasurementKind, Robot};
    /// let pose = Robot::ur5().with_measurement(MeasurementKind::Pose).unwrap();
    /// assert_eq!((pose.rows_per_pose(), pose.n_unknowns()), (6, 30));
    /// assert_eq!(pose.unknowns, Robot::builtin("ur5:pose").unwrap().unknowns);
    /// ```
    pub fn with_measurement(&self, m: MeasurementKind) -> Result<Robot> {
        let mut r = self.clone();
        r.measurement = m;
        let k = m.markers();
        for t in [&mut r.real, &mut r.nominal] {
            if k == 0 {
                t.markers.clear();
            } else if t.markers.len() != k {
                return Err(Error::Invalid(format!(
                    "{k} markers need {k} offsets in each parameter table (Robot::with_markers), not {}",
                    t.markers.len()
                )));
            }
        }
        if r.frames.is_empty() {
            return Err(Error::Invalid("the robot has no frames".into()));
        }
        if crate::measure::sensor_of(m, r.orientation_scale).observes_orientation() {
            let last = r.frames.len() - 1;
            if r.frames[last].joint.is_none() {
                if r.frames[last].convention == Convention::Dh {
                    r.frames[last].convention = Convention::Hayati;
                    r.real.rows[last][4] = 0.0;
                    r.nominal.rows[last][4] = 0.0;
                }
            } else {
                let mut label = "tool".to_string();
                while r.frames.iter().any(|f| f.label == label) {
                    label.push('_');
                }
                r.frames
                    .push(crate::model::Frame::fixed(&label, Convention::Hayati));
                r.real.rows.push([0.0; 5]);
                r.nominal.rows.push([0.0; 5]);
            }
        }
        r.unknowns = r.choose_unknowns(&self.unknowns)?;
        r.validate()?;
        r.check_identifiable()?;
        Ok(r)
    }
}

impl Robot {
    /// A copy measured by `offsets.len()` markers ([`MeasurementKind::Markers`])
    /// at these offsets in the last frame (nominal and real alike), its
    /// unknowns re-chosen as in [`Robot::with_measurement`] with the offsets'
    /// columns taken first. Errors on no offsets or a non-finite one.
    ///
    /// ```
    /// use activecal::model::Robot;
    /// let ur5 = Robot::ur5();
    /// let m = ur5.with_markers(&[[0.1, 0.0, 0.05], [0.0, 0.1, 0.05], [0.0, 0.0, 0.15]]).unwrap();
    /// // The offsets absorb the tool frame: 4 per revolute joint, 3 per marker.
    /// assert_eq!((m.rows_per_pose(), m.n_params()), (9, 4 * 6 + 9));
    /// assert_eq!(m.n_params(), m.minimal_unknowns());
    /// ```
    pub fn with_markers(&self, offsets: &[[f64; 3]]) -> Result<Robot> {
        if offsets.is_empty() {
            return Err(Error::Invalid(
                "a marker sensor needs at least one marker".into(),
            ));
        }
        if let Some(k) = offsets
            .iter()
            .position(|o| o.iter().any(|v| !v.is_finite()))
        {
            return Err(Error::Invalid(format!(
                "marker {}: the offset {:?} is not finite",
                k + 1,
                offsets[k]
            )));
        }
        let mut r = self.clone();
        r.real.markers = offsets.to_vec();
        r.nominal.markers = offsets.to_vec();
        r.with_measurement(MeasurementKind::Markers(offsets.len()))
    }

    /// The shape the kinematics needs (see [`Robot::validate`] for the
    /// rest): a table row per frame, joint numbers within the limits.
    fn check_shape(&self) -> Result<()> {
        for t in [&self.real, &self.nominal] {
            if t.rows.len() != self.frames.len() {
                return Err(Error::Invalid(format!(
                    "parameter table has {} rows for {} frames",
                    t.rows.len(),
                    self.frames.len()
                )));
            }
        }
        if let Some(f) = self
            .frames
            .iter()
            .find(|f| f.joint.is_some_and(|j| j >= self.dof()))
        {
            return Err(Error::Invalid(format!(
                "frame {}: joint index out of range ({} joint limits)",
                f.label,
                self.dof()
            )));
        }
        Ok(())
    }
}

/// `n` generic configurations of the robot, seeded: each joint drawn
/// uniformly over its whole range, and a revolute joint whose range spans a
/// turn or more over one turn from its lower limit (the angles beyond
/// repeat, modulo 2π, the kinematics of those within). Never levels: the
/// values of a lattice coincide modulo 2π on a joint whose limits are ±2π
/// (5 levels of [−2π, 2π] are only the angles 0 and π), and such a sample
/// leaves directions unseen that any real data set determines.
#[must_use]
pub fn generic_configurations(robot: &Robot, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let revolute: Vec<bool> = (0..robot.dof())
        .map(|j| {
            !robot
                .frames
                .iter()
                .any(|f| f.joint == Some(j) && f.is_prismatic())
        })
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            robot
                .limits
                .iter()
                .zip(&revolute)
                .map(|(&[lo, hi], &rev)| {
                    let hi = if rev {
                        hi.min(lo + std::f64::consts::TAU)
                    } else {
                        hi
                    };
                    let f: f64 = rng.random();
                    lo + (hi - lo) * f
                })
                .collect()
        })
        .collect()
}

/// The stacked identification Jacobian of `n` [generic
/// configurations](generic_configurations) at `table`, or an error if any
/// entry is not finite.
pub fn design_jacobian(robot: &Robot, table: &ParamTable, n: usize, seed: u64) -> Result<Blocks> {
    robot.check_shape()?;
    if robot.unknowns.is_empty() || table.rows.len() != robot.frames.len() {
        return Err(Error::Invalid(format!(
            "robot {}: no unknowns, or a table that does not fit the frames",
            robot.name
        )));
    }
    let qs = generic_configurations(robot, n, seed);
    let x = jacobian_of(robot, table, n, |i, q| q.copy_from_slice(&qs[i]));
    let m = x.mat();
    let finite = (0..m.ncols()).all(|c| (0..m.nrows()).all(|r| m[(r, c)].is_finite()));
    if !finite {
        return Err(Error::Invalid(format!(
            "robot {}: the kinematics is not finite on the joint ranges (parameters or limits too large)",
            robot.name
        )));
    }
    Ok(x)
}
