//! Numeric CSV tables as users export them: a header of column names, then
//! one row of numbers per line. Blank lines and lines starting with `#` are
//! skipped; cells are separated by commas and trimmed; a header cell may be
//! quoted (`"x1"`). Every error names the file, the 1-based line and column
//! and the column's name.

use crate::error::{Error, Result};

/// A parsed table: column names and rows of finite-or-not numbers, with the
/// file line of each row (for messages about a row's meaning, e.g. a joint
/// value out of its limits).
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// Column names, as in the header (trimmed, unquoted).
    pub columns: Vec<String>,
    /// Rows, each with one value per column.
    pub rows: Vec<Vec<f64>>,
    /// The 1-based file line of each row.
    pub lines: Vec<usize>,
}

impl Table {
    /// The index of a column by name.
    #[must_use]
    pub fn column(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }
}

/// The lines of CSV `text` that hold data, with their 1-based numbers:
/// blank lines and `#` comments skipped, a Windows line end dropped.
pub(crate) fn csv_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
}

/// A CSV header's column names, trimmed and unquoted.
pub(crate) fn header_cells(header: &str) -> Vec<String> {
    header
        .split(',')
        .map(|c| c.trim().trim_matches('"').trim().to_string())
        .collect()
}

/// Parses CSV `text` (from `origin`, for messages). Errors on an empty file,
/// a duplicate or empty column name, a row with another number of cells than
/// the header, and a cell that is not a number (NaN and infinities are read
/// as such; the caller decides whether they are allowed).
pub fn parse_csv(text: &str, origin: &str) -> Result<Table> {
    let err = |message: String| Error::Parse {
        path: origin.to_string(),
        message,
    };
    let mut lines = csv_lines(text);
    let (hline, header) = lines
        .next()
        .ok_or_else(|| err("empty file: expected a header line of column names".into()))?;
    let columns = header_cells(header);
    for (i, c) in columns.iter().enumerate() {
        if c.is_empty() {
            return Err(err(format!(
                "line {hline}, column {}: empty column name in the header",
                i + 1
            )));
        }
        if columns[..i].contains(c) {
            return Err(err(format!(
                "line {hline}, column {}: column '{c}' appears twice in the header",
                i + 1
            )));
        }
        if c.parse::<f64>().is_ok() {
            return Err(err(format!(
                "line {hline}, column {}: the first line must name the columns (x1, y1, z1, joint names, …), but holds the number {c}",
                i + 1
            )));
        }
    }
    let mut rows = Vec::new();
    let mut at = Vec::new();
    for (line, l) in lines {
        let cells: Vec<&str> = l.split(',').collect();
        if cells.len() != columns.len() {
            return Err(err(format!(
                "line {line}: {} cells, but the header names {} columns",
                cells.len(),
                columns.len()
            )));
        }
        let row = cells
            .iter()
            .enumerate()
            .map(|(c, cell)| {
                let cell = cell.trim();
                cell.parse::<f64>().map_err(|_| {
                    err(format!(
                        "line {line}, column {} ('{}'): cannot read '{}' as a number",
                        c + 1,
                        columns[c],
                        cell.chars().take(40).collect::<String>()
                    ))
                })
            })
            .collect::<Result<Vec<f64>>>()?;
        rows.push(row);
        at.push(line);
    }
    if rows.is_empty() {
        return Err(err(format!(
            "no data: the header (line {hline}) is followed by no rows"
        )));
    }
    Ok(Table {
        columns,
        rows,
        lines: at,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_header_rows_and_lines() {
        let t = parse_csv("# comment\n\"a\", b\n1, 2\n\n3,4e-1\r\n", "t.csv").unwrap();
        assert_eq!(t.columns, ["a", "b"]);
        assert_eq!(t.rows, vec![vec![1.0, 2.0], vec![3.0, 0.4]]);
        assert_eq!(t.lines, [3, 5]);
        assert_eq!(t.column("b"), Some(1));
    }

    #[test]
    fn errors_name_line_column_and_name() {
        let e = parse_csv("a,b\n1,2\n3,x\n", "t.csv")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("t.csv: line 3, column 2 ('b'): cannot read 'x'"),
            "{e}"
        );
        let e = parse_csv("a,b\n1\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("line 2: 1 cells, but the header names 2"), "{e}");
        let e = parse_csv("a,a\n1,2\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("column 'a' appears twice"), "{e}");
        let e = parse_csv("1,2\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("must name the columns"), "{e}");
        assert!(
            parse_csv("", "t.csv")
                .unwrap_err()
                .to_string()
                .contains("empty file")
        );
        assert!(
            parse_csv("a\n", "t.csv")
                .unwrap_err()
                .to_string()
                .contains("no data")
        );
    }
}
