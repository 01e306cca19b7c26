//! Building a pool from its spec ([`PoolSpec::build`]): the source's
//! candidates generated (or a file's rows taken), the memory they need
//! checked first, every filter's verdict on each candidate computed once in
//! parallel, and the survivors kept with their stable ids and statistics.

use super::file::{self, read_configurations};
use super::lattice::Lattice;
use super::sampled::{Sobol, Uniform};
use super::{Configurations, Pool, PoolFilter, PoolSource, PoolSpec, PoolStats, stats, turn};
use crate::error::{Error, Result};
use crate::model::{ParamTable, Robot};
use rayon::prelude::*;
use std::path::Path;

/// The generated candidates of a source, each computable from its id.
enum Candidates<'a> {
    Lattice(Lattice),
    Random(Uniform),
    Sobol(Sobol),
    Listed(&'a [Vec<f64>]),
}

impl Candidates<'_> {
    fn size(&self) -> usize {
        match self {
            Candidates::Lattice(l) => l.size(),
            Candidates::Random(u) => u.size(),
            Candidates::Sobol(s) => s.size(),
            Candidates::Listed(rows) => rows.len(),
        }
    }

    fn q_into(&self, id: usize, q: &mut [f64]) {
        match self {
            Candidates::Lattice(l) => l.q_into(id, q),
            Candidates::Random(u) => u.q_into(id, q),
            Candidates::Sobol(s) => s.q_into(id, q),
            Candidates::Listed(rows) => q.copy_from_slice(&rows[id]),
        }
    }
}

impl PoolSpec {
    /// The robot with the margin taken off its joint limits (itself without
    /// a margin); an error names a joint whose range the margin empties.
    fn margined(&self, robot: &Robot) -> Result<Option<Robot>> {
        if self.margin == 0.0 {
            return Ok(None);
        }
        let names = file::joint_names(robot);
        let limits = turn::shrunk_limits(robot, &names, self.margin)?;
        let mut r = robot.clone();
        r.limits = limits;
        Ok(Some(r))
    }

    /// Builds the pool for `robot`: generates the source's configurations
    /// (reading the file of a [`PoolSource::File`]) and keeps those that
    /// pass every filter (evaluated at `table`, the model the sensor region
    /// is known in, usually the nominal one). A pool that the filters leave
    /// empty is an error naming the filter that removed the last candidates,
    /// and so is a filter whose region is malformed ([`crate::measure::Visibility::validate`]).
    pub fn build(&self, robot: &Robot, table: &ParamTable) -> Result<Pool> {
        self.build_budgeted(robot, table, true)
    }

    /// Builds the pool as [`PoolSpec::build`] does, for a caller that only
    /// lists or counts its poses: the memory budget counts the poses, not
    /// the Jacobian such a caller never builds.
    pub fn build_poses(&self, robot: &Robot, table: &ParamTable) -> Result<Pool> {
        self.build_budgeted(robot, table, false)
    }

    fn build_budgeted(&self, robot: &Robot, table: &ParamTable, jacobian: bool) -> Result<Pool> {
        self.validate_filters(robot)?;
        match &self.source {
            PoolSource::File { path } => {
                let rows = read_configurations(Path::new(path), robot)?;
                self.listed(robot, table, rows, jacobian)
            }
            _ => self.build_inner(robot, table, None, Vec::new(), jacobian),
        }
    }

    /// Checks every filter's own settings (a malformed region) and loads
    /// the collision models, from the URDF text `robot` was imported from
    /// when they name its file (so that the file is read once).
    fn validate_filters(&self, robot: &Robot) -> Result<()> {
        let source = robot
            .source
            .as_ref()
            .map(|s| (s.path.as_str(), s.text.as_str()));
        for f in &self.filters {
            match f {
                PoolFilter::Visibility(v) => v
                    .validate()
                    .map_err(|e| Error::Invalid(format!("visibility filter: {e}")))?,
                PoolFilter::Collision(c) => {
                    c.load_sharing(source)
                        .map_err(|e| Error::Invalid(format!("{} filter: {e}", c.kind())))?;
                }
                PoolFilter::Camera(c) => c
                    .validate()
                    .map_err(|e| Error::Invalid(format!("camera view filter: {e}")))?,
            }
        }
        Ok(())
    }

    /// Builds a [`PoolSource::File`] pool from its rows as already read (the
    /// file's configurations stored in a design file, so that the design
    /// needs no access to the original file). Errors for another source.
    pub fn build_listed(
        &self,
        robot: &Robot,
        table: &ParamTable,
        rows: Configurations,
    ) -> Result<Pool> {
        self.validate_filters(robot)?;
        self.listed(robot, table, rows, true)
    }

    fn listed(
        &self,
        robot: &Robot,
        table: &ParamTable,
        rows: Configurations,
        jacobian: bool,
    ) -> Result<Pool> {
        if !matches!(self.source, PoolSource::File { .. }) {
            return Err(Error::Invalid(format!(
                "stored configurations given for a {} pool",
                self.source.kind()
            )));
        }
        let dof = robot.dof();
        if let Some(k) = rows
            .qs
            .iter()
            .position(|q| q.len() != dof || q.iter().any(|v| !v.is_finite()))
        {
            return Err(Error::Invalid(format!(
                "configuration {k} of the pool has {} joint values (the robot {dof}), or one is not finite",
                rows.qs[k].len()
            )));
        }
        self.build_inner(robot, table, Some(rows.qs), rows.notes, jacobian)
    }

    fn build_inner(
        &self,
        robot: &Robot,
        table: &ParamTable,
        rows: Option<Vec<Vec<f64>>>,
        notes: Vec<String>,
        jacobian: bool,
    ) -> Result<Pool> {
        let margined = self.margined(robot)?;
        let inside = margined.as_ref().unwrap_or(robot);
        let n = match self.source.declared_size(inside)? {
            Some(n) => n,
            None => rows.as_ref().map_or(0, Vec::len),
        };
        check_memory(robot, n, jacobian)?;
        let cands = self.candidates(robot, inside, rows.as_deref())?;
        let dof = robot.dof();
        // A file's rows are checked against the margin first (generated
        // sources are made inside it).
        let margin_limits = match (&cands, &margined) {
            (Candidates::Listed(_), Some(m)) => Some(m.limits.clone()),
            _ => None,
        };
        let mut names: Vec<String> = Vec::new();
        if margin_limits.is_some() {
            names.push("margin".into());
        }
        names.extend(self.filters.iter().map(|f| f.kind().to_string()));
        let verdict = self.verdicts(robot, table, &cands, margin_limits.as_deref(), names.len());
        let ids: Vec<usize> = (0..cands.size())
            .filter(|&id| verdict.get(id).is_none_or(|v| v.0 == names.len()))
            .collect();
        let mut models = vec![None; usize::from(margin_limits.is_some())];
        models.extend(self.filters.iter().map(|f| match f {
            PoolFilter::Collision(c) => c.load().ok(),
            PoolFilter::Visibility(_) | PoolFilter::Camera(_) => None,
        }));
        let filters = stats::filter_stats(&names, &models, &verdict, cands.size());
        debug_assert_eq!(
            filters.last().map_or(cands.size(), |f| f.seen - f.removed),
            ids.len()
        );
        if ids.is_empty() {
            return Err(Error::Invalid(stats::emptied(&filters, cands.size())));
        }
        let mut q = vec![0.0; ids.len() * dof];
        if dof > 0 {
            q.par_chunks_mut(dof)
                .zip(ids.par_iter())
                .for_each(|(row, &id)| cands.q_into(id, row));
        }
        let stats = PoolStats {
            candidates: cands.size(),
            filters,
            kept: ids.len(),
            notes,
        };
        let source_size = cands.size();
        let lattice = match cands {
            Candidates::Lattice(l) => Some(l),
            _ => None,
        };
        Ok(Pool {
            spec: self.clone(),
            dof,
            q,
            ids,
            lattice,
            source_size,
            stats,
            listed: rows,
        })
    }

    /// The source's candidates, generated inside `inside`'s limits (the
    /// robot with the margin applied), or a file's rows as given.
    fn candidates<'r>(
        &self,
        robot: &Robot,
        inside: &Robot,
        rows: Option<&'r [Vec<f64>]>,
    ) -> Result<Candidates<'r>> {
        Ok(match (&self.source, rows) {
            (PoolSource::Lattice { levels }, _) => {
                Candidates::Lattice(Lattice::within(robot, *levels, &inside.limits)?)
            }
            (PoolSource::Random { count, seed }, _) => {
                Candidates::Random(Uniform::new(inside, *count, *seed)?)
            }
            (PoolSource::Sobol { count, seed }, _) => {
                Candidates::Sobol(Sobol::new(inside, *count, *seed)?)
            }
            (PoolSource::File { .. }, Some(rows)) => Candidates::Listed(rows),
            (PoolSource::File { .. }, None) => unreachable!("a file source is built from its rows"),
        })
    }

    /// For each candidate, the first filter that removes it (`n_filters`:
    /// none; filter 0 is the margin when `margin_limits` is given) and, for
    /// a collision filter, the contact that did (`NO_CONTACT` otherwise);
    /// empty when there is no filter. Each candidate's verdict once (a
    /// collision check is the costly filter), in parallel over fixed chunks,
    /// with progress. Integer counts: the same whatever the thread split.
    fn verdicts(
        &self,
        robot: &Robot,
        table: &ParamTable,
        cands: &Candidates<'_>,
        margin_limits: Option<&[[f64; 2]]>,
        n_filters: usize,
    ) -> Vec<(usize, usize)> {
        if n_filters == 0 {
            return Vec::new();
        }
        let dof = robot.dof();
        let skip = usize::from(margin_limits.is_some());
        let first_fail = |id: usize| -> (usize, usize) {
            let mut q = vec![0.0; dof];
            cands.q_into(id, &mut q);
            if let Some(m) = margin_limits
                && q.iter().zip(m).any(|(v, l)| *v < l[0] || *v > l[1])
            {
                return (0, stats::NO_CONTACT);
            }
            for (k, f) in self.filters.iter().enumerate() {
                match f {
                    PoolFilter::Collision(c) => {
                        if let Some(key) = c.contact_key(&q) {
                            return (k + skip, key);
                        }
                    }
                    _ if !f.keeps(robot, table, &q) => return (k + skip, stats::NO_CONTACT),
                    _ => {}
                }
            }
            (n_filters, stats::NO_CONTACT)
        };
        let task = crate::progress::Task::start("pool filters", Some(cands.size() as u64));
        let mut v = vec![(n_filters, stats::NO_CONTACT); cands.size()];
        v.par_chunks_mut(1024).enumerate().for_each(|(c, chunk)| {
            for (k, out) in chunk.iter_mut().enumerate() {
                *out = first_fail(c * 1024 + k);
            }
            task.inc(chunk.len() as u64);
        });
        v
    }
}

/// Bytes a pool of `n` candidates takes through selection: its id and joint
/// values, its identification Jacobian (`t·p` values a pose), and one
/// workspace of the Jacobian's size (the pool variances' `Y = X L⁻ᵀ`, the
/// bound's scaled copy). The same for every source: `n` is the number of
/// candidates before filtering (lattice size, sample count, or rows of a
/// file), an upper bound of the pool's size.
#[must_use]
pub fn memory_estimate(robot: &Robot, n: usize) -> u64 {
    let per_pose = 8 * (1 + robot.dof() + 2 * robot.rows_per_pose() * robot.n_params());
    crate::resources::bytes_of(n, per_pose)
}

/// Bytes a pool of `n` candidates takes when only its poses are listed:
/// ids, joint values and each candidate's filter verdict.
#[must_use]
pub fn poses_memory_estimate(robot: &Robot, n: usize) -> u64 {
    crate::resources::bytes_of(n, 8 * (1 + robot.dof()) + 16)
}

/// Refuses, before anything is allocated, a pool whose
/// [`memory_estimate`] (with its Jacobian) or [`poses_memory_estimate`]
/// (without) exceeds the memory budget.
fn check_memory(robot: &Robot, n: usize, jacobian: bool) -> Result<()> {
    let budget = crate::resources::MemoryBudget::from_env()?;
    if !jacobian {
        return budget.check(
            &format!("a pool of {n} poses"),
            poses_memory_estimate(robot, n),
        );
    }
    budget.check(
        &format!(
            "a pool of {n} poses (its {}×{} Jacobian and a workspace)",
            n.saturating_mul(robot.rows_per_pose()),
            robot.n_params()
        ),
        memory_estimate(robot, n),
    )
}
