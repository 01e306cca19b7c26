//! The `/tf` and `/tf_static` trees: the transform from one frame to
//! another as a time series, composed along the tree's path. Static
//! transforms (and any transform that never changes) are composed with at
//! most one moving transform; a path through two moving transforms would
//! need their stamps interpolated, and is refused.

use super::messages::{self, Stamped};
use super::timeseries::MeasSeries;
use super::{Bag, BagError, RawMessage};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use std::collections::HashMap;

/// The tf topics of `bag` (`/tf`, `/tf_static`), checked to be
/// `TFMessage`s; an error when neither is there.
pub fn topics(bag: &Bag) -> Result<Vec<String>, BagError> {
    let names: Vec<String> = ["/tf", "/tf_static"]
        .into_iter()
        .filter(|n| bag.topics().iter().any(|t| t.name == *n))
        .map(String::from)
        .collect();
    if names.is_empty() {
        bag.topic("/tf", &[messages::TF_MESSAGE])?;
    }
    for n in &names {
        bag.topic(n, &[messages::TF_MESSAGE])?;
    }
    Ok(names)
}

/// One edge's samples: stamps and transforms (parent ← child).
#[derive(Clone, Debug, Default)]
struct Edge {
    t: Vec<f64>,
    x: Vec<Isometry3<f64>>,
}

impl Edge {
    fn moves(&self) -> bool {
        self.x.windows(2).any(|w| {
            (w[0].translation.vector - w[1].translation.vector).norm() > 1e-12
                || w[0].rotation.angle_to(&w[1].rotation) > 1e-12
        })
    }
}

/// The transforms read, by (parent, child).
#[derive(Clone, Debug, Default)]
pub struct Tree {
    edges: HashMap<(String, String), Edge>,
}

fn isometry(s: &Stamped) -> Isometry3<f64> {
    let [w, x, y, z] = s.orientation.unwrap_or([1.0, 0.0, 0.0, 0.0]);
    let [px, py, pz] = s.position;
    Isometry3::from_parts(
        Translation3::new(px, py, pz),
        UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)),
    )
}

impl Tree {
    /// Adds a `TFMessage`'s transforms.
    pub fn add(&mut self, bag: &Bag, m: &RawMessage<'_>) -> Result<(), BagError> {
        let list = messages::tf_message(m.data).map_err(|e| bag.decode_error(m, e))?;
        for s in list {
            let e = self
                .edges
                .entry((s.header.frame_id.clone(), s.child_frame_id.clone()))
                .or_default();
            e.t.push(s.header.stamp);
            e.x.push(isometry(&s));
        }
        Ok(())
    }

    /// The path from `from` to `to`: edges with their direction (true when
    /// walked from parent to child).
    fn path(&self, from: &str, to: &str) -> Option<Vec<(&(String, String), bool)>> {
        let mut prev: HashMap<&str, (&(String, String), bool, &str)> = HashMap::new();
        let mut queue = std::collections::VecDeque::from([from]);
        let mut seen = std::collections::HashSet::from([from]);
        while let Some(f) = queue.pop_front() {
            if f == to {
                let mut out = Vec::new();
                let mut at = to;
                while at != from {
                    let (k, dir, back) = prev[at];
                    out.push((k, dir));
                    at = back;
                }
                out.reverse();
                return Some(out);
            }
            for k in self.edges.keys() {
                let next = if k.0 == f {
                    Some((k.1.as_str(), true))
                } else if k.1 == f {
                    Some((k.0.as_str(), false))
                } else {
                    None
                };
                if let Some((n, dir)) = next
                    && seen.insert(n)
                {
                    prev.insert(n, (k, dir, f));
                    queue.push_back(n);
                }
            }
        }
        None
    }

    /// The transform from `parent` to `child` (the child's pose in the
    /// parent's frame) at each stamp of the path's one moving transform.
    pub fn chain(&self, bag: &Bag, parent: &str, child: &str) -> Result<MeasSeries, BagError> {
        let Some(path) = self.path(parent, child) else {
            let mut frames: Vec<&str> = self
                .edges
                .keys()
                .flat_map(|(a, b)| [a.as_str(), b.as_str()])
                .collect();
            frames.sort_unstable();
            frames.dedup();
            return Err(bag.content_error(format!(
                "/tf: no chain of transforms from '{parent}' to '{child}' (the frames: {})",
                frames.join(", ")
            )));
        };
        let moving: Vec<usize> = (0..path.len())
            .filter(|&i| self.edges[path[i].0].moves())
            .collect();
        let Some(&m) = moving.first() else {
            return Err(bag.content_error(format!(
                "/tf: the transform from '{parent}' to '{child}' never changes: it measures nothing"
            )));
        };
        if moving.len() > 1 {
            let names: Vec<String> = moving
                .iter()
                .map(|&i| format!("{} → {}", path[i].0.0, path[i].0.1))
                .collect();
            return Err(bag.content_error(format!(
                "/tf: the chain from '{parent}' to '{child}' has {} moving transforms ({}); one is read",
                names.len(),
                names.join(", ")
            )));
        }
        let fixed = |i: usize| {
            let e = &self.edges[path[i].0];
            let x = *e.x.last().expect("an edge has a sample");
            if path[i].1 { x } else { x.inverse() }
        };
        let before = (0..m).fold(Isometry3::identity(), |a, i| a * fixed(i));
        let after = (m + 1..path.len()).fold(Isometry3::identity(), |a, i| a * fixed(i));
        let e = &self.edges[path[m].0];
        let mut out = MeasSeries::default();
        for (t, x) in e.t.iter().zip(&e.x) {
            let x = if path[m].1 { *x } else { x.inverse() };
            let total = before * x * after;
            let v = total.translation.vector;
            let q = total.rotation;
            out.t.push(*t);
            out.p.push([v.x, v.y, v.z]);
            out.r.push([q.w, q.i, q.j, q.k]);
        }
        Ok(out)
    }
}
