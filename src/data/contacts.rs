//! Contacts as read from a file: each row's joint values, the point or
//! plane it touches and its file line ([`crate::io::contacts`] reads them).

use crate::measure::contact::{Plane, PlaneKind};
use serde::Serialize;

/// Contacts read from a file.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactFile {
    /// The file, for messages.
    pub origin: String,
    /// Joint values of each row (radians, metres).
    pub qs: Vec<Vec<f64>>,
    /// What each row touches: point `g` for `g < points.len()`, else plane
    /// `g − points.len()` (the contact sensor's tags).
    pub groups: Vec<usize>,
    /// Point names, in order of first appearance.
    pub points: Vec<String>,
    /// Planes, in order of first appearance (unknown unless made known by
    /// [`ContactFile::set_known_planes`]).
    pub planes: Vec<Plane>,
    /// The 1-based file line of each row.
    pub lines: Vec<usize>,
}

/// A plane `n · x = d` known by name (base frame, metres; `n` any non-zero
/// length, normalised when set).
#[derive(Clone, Debug, PartialEq)]
pub struct NamedPlane {
    /// The plane's name (as in the file's `plane` column).
    pub name: String,
    /// Its normal.
    pub normal: [f64; 3],
    /// Its offset `d`, metres.
    pub offset: f64,
}

/// Different configurations a fit needs for each point (its 3 unknown
/// coordinates) and each plane (3 points span it).
pub const MIN_DISTINCT: usize = 3;

impl ContactFile {
    /// Refuses a point or plane with fewer than [`MIN_DISTINCT`] different
    /// configurations: the same configuration recorded again adds nothing,
    /// and a fit of such rows has nothing to determine. The error names the
    /// point, its lines and the file.
    pub fn check_distinct(&self) -> crate::error::Result<()> {
        let min = MIN_DISTINCT;
        let names = self
            .points
            .iter()
            .map(|p| ("point", p.as_str()))
            .chain(self.planes.iter().map(|p| ("plane", p.name.as_str())));
        for (g, (what, name)) in names.enumerate() {
            let rows: Vec<usize> = (0..self.qs.len())
                .filter(|&k| self.groups[k] == g)
                .collect();
            let mut distinct: Vec<&Vec<f64>> = Vec::new();
            for &k in &rows {
                if !distinct.contains(&&self.qs[k]) {
                    distinct.push(&self.qs[k]);
                }
            }
            if distinct.len() < min {
                let mut at: Vec<String> = rows
                    .iter()
                    .take(6)
                    .map(|&k| self.lines[k].to_string())
                    .collect();
                if rows.len() > 6 {
                    at.push("…".into());
                }
                return Err(crate::error::Error::Parse {
                    path: self.origin.clone(),
                    message: format!(
                        "{what} '{name}' has {} rows (line {}) but {} different configuration(s): a fit needs at least {min} different ones a {what} (a row recorded again adds nothing)",
                        rows.len(),
                        at.join(", "),
                        distinct.len()
                    ),
                });
            }
        }
        Ok(())
    }
    /// The index of a point by name.
    #[must_use]
    pub fn point_index(&self, name: &str) -> Option<usize> {
        self.points.iter().position(|p| p == name)
    }

    /// The name of what group `g` touches (a point or a plane).
    #[must_use]
    pub fn name_of(&self, g: usize) -> &str {
        match g.checked_sub(self.points.len()) {
            Some(l) => &self.planes[l].name,
            None => &self.points[g],
        }
    }

    /// Rows touching point (or plane) `g`.
    #[must_use]
    pub fn rows_of(&self, g: usize) -> Vec<usize> {
        (0..self.groups.len())
            .filter(|&i| self.groups[i] == g)
            .collect()
    }

    /// Makes the planes of `known` known (normal normalised). Errors on a
    /// name the file has no plane of, and on a zero or non-finite normal or
    /// offset, naming the plane.
    pub fn set_known_planes(&mut self, known: &[NamedPlane]) -> crate::error::Result<()> {
        for k in known {
            let len = k.normal.iter().map(|c| c * c).sum::<f64>().sqrt();
            if !(len.is_finite() && len > 0.0 && k.offset.is_finite()) {
                return Err(crate::error::Error::Invalid(format!(
                    "plane '{}': normal ({}, {}, {}) with offset {} m: the normal must be non-zero and finite (a plane needs a direction)",
                    k.name, k.normal[0], k.normal[1], k.normal[2], k.offset
                )));
            }
            let Some(p) = self.planes.iter_mut().find(|p| p.name == k.name) else {
                let names: Vec<&str> = self.planes.iter().map(|p| p.name.as_str()).collect();
                return Err(crate::error::Error::Invalid(format!(
                    "plane '{}': {} has no such plane (its planes: {})",
                    k.name,
                    self.origin,
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    }
                )));
            };
            p.kind = PlaneKind::Known {
                normal: k.normal.map(|c| c / len),
                offset: k.offset / len,
            };
        }
        Ok(())
    }

    /// The rows `rows` only (points and planes renumbered in order of
    /// appearance, points first).
    #[must_use]
    pub fn subset(&self, rows: &[usize]) -> Self {
        let mut points: Vec<String> = Vec::new();
        let mut planes: Vec<Plane> = Vec::new();
        let mut which = Vec::with_capacity(rows.len());
        for &i in rows {
            let g = self.groups[i];
            match g.checked_sub(self.points.len()) {
                Some(l) => {
                    let p = &self.planes[l];
                    let k = planes
                        .iter()
                        .position(|q| q.name == p.name)
                        .unwrap_or_else(|| {
                            planes.push(p.clone());
                            planes.len() - 1
                        });
                    which.push(Err(k));
                }
                None => {
                    let name = &self.points[g];
                    let k = points.iter().position(|q| q == name).unwrap_or_else(|| {
                        points.push(name.clone());
                        points.len() - 1
                    });
                    which.push(Ok(k));
                }
            }
        }
        let groups = which
            .iter()
            .map(|w| match *w {
                Ok(k) => k,
                Err(l) => points.len() + l,
            })
            .collect();
        Self {
            origin: self.origin.clone(),
            qs: rows.iter().map(|&i| self.qs[i].clone()).collect(),
            groups,
            points,
            planes,
            lines: rows.iter().map(|&i| self.lines[i]).collect(),
        }
    }
}

/// A distance known between two named points.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NamedDistance {
    /// The first point's name.
    pub a: String,
    /// The second point's name.
    pub b: String,
    /// The distance, metres.
    pub metres: f64,
}

/// `NAME=v1,…,vN`: a non-empty name and exactly `N` numbers (`None`
/// otherwise): how a named plane and a named point are written as text.
#[must_use]
pub fn named_numbers<const N: usize>(s: &str) -> Option<(String, [f64; N])> {
    let (name, rest) = s.split_once('=')?;
    let v: Vec<f64> = rest
        .split(',')
        .map(|c| c.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .ok()?;
    let name = name.trim();
    (!name.is_empty()).then(|| v.try_into().ok().map(|a| (name.to_string(), a)))?
}

impl std::str::FromStr for NamedDistance {
    type Err = String;

    /// `A,B=METRES`: two point names and the distance between them.
    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || {
            "expected A,B=METRES (two point names and a distance in metres, e.g. front_left/0,front_left/1=0.05)"
                .to_string()
        };
        let (names, d) = s.split_once('=').ok_or_else(bad)?;
        let (a, b) = names.split_once(',').ok_or_else(bad)?;
        let metres: f64 = d.trim().parse().map_err(|_| bad())?;
        Ok(NamedDistance {
            a: a.trim().to_string(),
            b: b.trim().to_string(),
            metres,
        })
    }
}

impl std::str::FromStr for NamedPlane {
    type Err = String;

    /// `NAME=nx,ny,nz,d`: n · x = d in the base frame, metres (the
    /// normal's length is checked with the file's planes).
    fn from_str(s: &str) -> Result<Self, String> {
        let Some((name, [nx, ny, nz, d])) = named_numbers::<4>(s) else {
            return Err("expected NAME=nx,ny,nz,d (a plane name, its normal and offset in metres, n · x = d in the base frame, e.g. table=0,0,1,0.02)".into());
        };
        Ok(NamedPlane {
            name,
            normal: [nx, ny, nz],
            offset: d,
        })
    }
}
