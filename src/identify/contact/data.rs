//! Contacts as read from a file: each row's joint values, the point it
//! touches and its file line ([`crate::io::contacts`] reads them).

/// Contacts read from a file.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactFile {
    /// The file, for messages.
    pub origin: String,
    /// Joint values of each row (radians, metres).
    pub qs: Vec<Vec<f64>>,
    /// The point each row touches (an index into `points`).
    pub groups: Vec<usize>,
    /// Point names, in order of first appearance.
    pub points: Vec<String>,
    /// The 1-based file line of each row.
    pub lines: Vec<usize>,
}

impl ContactFile {
    /// The index of a point by name.
    #[must_use]
    pub fn point_index(&self, name: &str) -> Option<usize> {
        self.points.iter().position(|p| p == name)
    }

    /// Rows touching point `g`.
    #[must_use]
    pub fn rows_of(&self, g: usize) -> Vec<usize> {
        (0..self.groups.len())
            .filter(|&i| self.groups[i] == g)
            .collect()
    }

    /// The rows `rows` only (points renumbered in order of appearance).
    #[must_use]
    pub fn subset(&self, rows: &[usize]) -> Self {
        let mut points: Vec<String> = Vec::new();
        let mut groups = Vec::with_capacity(rows.len());
        for &i in rows {
            let name = &self.points[self.groups[i]];
            let g = match points.iter().position(|p| p == name) {
                Some(g) => g,
                None => {
                    points.push(name.clone());
                    points.len() - 1
                }
            };
            groups.push(g);
        }
        Self {
            origin: self.origin.clone(),
            qs: rows.iter().map(|&i| self.qs[i].clone()).collect(),
            groups,
            points,
            lines: rows.iter().map(|&i| self.lines[i]).collect(),
        }
    }
}
