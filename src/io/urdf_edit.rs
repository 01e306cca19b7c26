//! A calibrated URDF: the user's own file with only the `<origin>` of some
//! joints changed. Every other byte — names, links off the chain, meshes,
//! inertials, transmissions, ros2_control and Gazebo tags, comments,
//! indentation — is copied as it was: the file is edited in place at the
//! byte ranges `roxmltree` gives for the origin attributes.

use crate::error::{Error, Result};
use crate::model::source::rpy;
use nalgebra::Isometry3;
use std::ops::Range;

/// A number as the shortest decimal that reads back to the same `f64`.
fn num(v: f64) -> String {
    // `{}` of an f64 is its shortest round-trip form; −0 reads as 0.
    if v == 0.0 { "0".into() } else { format!("{v}") }
}

/// `xyz` and `rpy` attribute values of an origin.
fn values(t: &Isometry3<f64>) -> (String, String) {
    let v = t.translation.vector;
    let r = rpy(&t.rotation.to_rotation_matrix());
    (
        format!("{} {} {}", num(v.x), num(v.y), num(v.z)),
        format!("{} {} {}", num(r[0]), num(r[1]), num(r[2])),
    )
}

/// One replacement of the text: a byte range and what goes there.
struct Edit {
    range: Range<usize>,
    text: String,
}

/// The edits that give joint `joint` (an element) the origin `t`.
fn edits_for(text: &str, joint: roxmltree::Node<'_, '_>, t: &Isometry3<f64>) -> Vec<Edit> {
    let (xyz, rpy) = values(t);
    let origin = joint
        .children()
        .find(|c| c.is_element() && c.tag_name().name() == "origin");
    let Some(origin) = origin else {
        // No <origin> (identity): insert one as the joint's first child,
        // after the start tag, indented as the joint's first element child.
        let start_end = start_tag_end(text, joint.range().start);
        let indent = joint
            .children()
            .find(|c| c.is_element())
            .map(|c| line_indent(text, c.range().start))
            .unwrap_or_else(|| format!("{}  ", line_indent(text, joint.range().start)));
        return vec![Edit {
            range: start_end..start_end,
            text: format!("\n{indent}<origin xyz=\"{xyz}\" rpy=\"{rpy}\"/>"),
        }];
    };
    let mut edits = Vec::new();
    let mut missing = Vec::new();
    for (name, value) in [("xyz", xyz), ("rpy", rpy)] {
        match origin.attributes().find(|a| a.name() == name) {
            Some(a) => edits.push(Edit {
                range: a.range_value(),
                text: value,
            }),
            None => missing.push(format!(" {name}=\"{value}\"")),
        }
    }
    if !missing.is_empty() {
        // After the element's name: `<origin` is 7 bytes.
        let at = origin.range().start + "<origin".len();
        edits.push(Edit {
            range: at..at,
            text: missing.concat(),
        });
    }
    edits
}

/// Byte just after the `>` ending the start tag that begins at `start`.
fn start_tag_end(text: &str, start: usize) -> usize {
    let mut quote = None;
    for (i, c) in text[start..].char_indices() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (None, '"' | '\'') => quote = Some(c),
            (None, '>') => return start + i + 1,
            _ => {}
        }
    }
    text.len()
}

/// The whitespace before `at` on its line.
fn line_indent(text: &str, at: usize) -> String {
    let line = text[..at].rfind('\n').map_or(0, |i| i + 1);
    text[line..at]
        .chars()
        .take_while(|c| c.is_whitespace())
        .collect()
}

/// The URDF `text` (from `path`, for messages) with the `<origin>` of each
/// named joint set to its transform (xyz in metres, rpy in radians as URDF
/// reads them). Errors when the text is not XML or a joint is not in it.
pub fn with_origins(
    text: &str,
    path: &str,
    origins: &[(String, Isometry3<f64>)],
) -> Result<String> {
    let opts = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..roxmltree::ParsingOptions::default()
    };
    let doc = roxmltree::Document::parse_with_options(text, opts).map_err(|e| Error::Parse {
        path: path.to_string(),
        message: format!("not XML: {e}"),
    })?;
    let mut edits = Vec::new();
    for (name, t) in origins {
        let joint = doc.root_element().children().find(|c| {
            c.is_element() && c.tag_name().name() == "joint" && c.attribute("name") == Some(name)
        });
        let Some(joint) = joint else {
            return Err(Error::Parse {
                path: path.to_string(),
                message: format!("no <joint name=\"{name}\"> under <robot>"),
            });
        };
        edits.extend(edits_for(text, joint, t));
    }
    edits.sort_by_key(|e| std::cmp::Reverse(e.range.start));
    let mut out = text.to_string();
    for e in edits {
        out.replace_range(e.range, &e.text);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    fn iso(x: f64, r: f64) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::new(x, 0.25, -1.5),
            UnitQuaternion::from_euler_angles(r, 0.0, 0.5),
        )
    }

    const URDF: &str = "<?xml version=\"1.0\"?>\n<!-- keep me -->\n<robot name=\"r\">\n  <link name=\"a\"/>\n  <joint name=\"j1\" type=\"revolute\">\n    <origin rpy=\"0 0 0\" xyz=\"1 2 3\"/>\n    <parent link=\"a\"/>\n  </joint>\n  <joint name=\"j2\" type=\"fixed\">\n    <parent link=\"a\"/>\n  </joint>\n  <joint name=\"j3\" type=\"fixed\">\n    <origin xyz=\"1 2 3\" />\n  </joint>\n</robot>\n";

    #[test]
    fn only_the_origins_change_and_they_read_back_exactly() {
        let out = with_origins(
            URDF,
            "r.urdf",
            &[
                ("j1".into(), iso(0.1, 0.2)),
                ("j2".into(), iso(-0.3, 0.1)),
                ("j3".into(), iso(0.7, -0.4)),
            ],
        )
        .unwrap();
        // Outside the origins, the text is the input's.
        assert!(out.starts_with("<?xml version=\"1.0\"?>\n<!-- keep me -->\n<robot name=\"r\">"));
        assert!(out.contains("<parent link=\"a\"/>\n  </joint>\n  <joint name=\"j3\""));
        let doc = roxmltree::Document::parse(&out).unwrap();
        for (name, t) in [
            ("j1", iso(0.1, 0.2)),
            ("j2", iso(-0.3, 0.1)),
            ("j3", iso(0.7, -0.4)),
        ] {
            let j = doc
                .descendants()
                .find(|n| n.attribute("name") == Some(name))
                .unwrap();
            let o = j
                .children()
                .find(|c| c.tag_name().name() == "origin")
                .unwrap();
            let parse = |a: &str| -> Vec<f64> {
                o.attribute(a)
                    .unwrap()
                    .split_whitespace()
                    .map(|v| v.parse().unwrap())
                    .collect()
            };
            let (x, r) = (parse("xyz"), parse("rpy"));
            let back = Isometry3::from_parts(
                Translation3::new(x[0], x[1], x[2]),
                UnitQuaternion::from_euler_angles(r[0], r[1], r[2]),
            );
            // Shortest round-trip decimals: the transform rebuilds to
            // rounding of the rpy conversion (a few ulps).
            assert!(
                (back.to_homogeneous() - t.to_homogeneous()).abs().max() < 1e-15,
                "{name}"
            );
        }
    }

    #[test]
    fn a_missing_joint_is_named() {
        let e = with_origins(URDF, "r.urdf", &[("nope".into(), iso(0.0, 0.0))]).unwrap_err();
        assert!(e.to_string().contains("nope") && e.to_string().contains("r.urdf"));
    }
}
