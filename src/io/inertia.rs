//! The gravity model of a URDF robot ([`crate::model::gravity`]): the link
//! tree and joints of the URDF the chain came from
//! ([`crate::model::Robot::source`]), each link's `<inertial>` mass and
//! centre of mass — from the same file, or from another URDF with the same
//! link names — and an optional payload on the tip link.

use crate::error::{Error, Result};
use crate::model::gravity::{GravityModel, LinkMass, TreeJoint};
use crate::model::{JointKind, Robot};
use nalgebra::{Isometry3, Rotation3, Translation3, UnitQuaternion, Vector3};
use std::collections::HashMap;

/// A point mass carried by the tip link.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Payload {
    /// Mass, kg.
    pub mass: f64,
    /// Position in the tip link's frame, m.
    pub at: [f64; 3],
}

impl std::str::FromStr for Payload {
    type Err = String;

    /// `KG[@X,Y,Z]`: the mass in kg, at a point of the tip link's frame in
    /// metres (its origin when not given).
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let (m, at) = match s.split_once('@') {
            Some((m, at)) => (m, Some(at)),
            None => (s, None),
        };
        let mass: f64 = m
            .trim()
            .parse()
            .map_err(|_| format!("'{m}' is not a mass in kg (KG or KG@X,Y,Z)"))?;
        if !(mass.is_finite() && mass >= 0.0) {
            return Err(format!("{mass} kg: the mass must be finite and >= 0"));
        }
        let at = match at {
            None => [0.0; 3],
            Some(a) => {
                let v: Vec<f64> = a
                    .split(',')
                    .map(|x| x.trim().parse::<f64>())
                    .collect::<std::result::Result<_, _>>()
                    .map_err(|_| format!("'{a}' is not X,Y,Z in metres"))?;
                if v.len() != 3 || !v.iter().all(|x| x.is_finite()) {
                    return Err(format!("'{a}' is not three finite numbers X,Y,Z (metres)"));
                }
                [v[0], v[1], v[2]]
            }
        };
        Ok(Payload { mass, at })
    }
}

/// Where the masses come from.
#[derive(Clone, Debug, Default)]
pub struct InertiaOptions {
    /// Another URDF's text and its name, whose `<inertial>` elements replace
    /// the robot's own (links matched by name).
    pub inertials: Option<(String, String)>,
    /// A payload on the tip link.
    pub payload: Option<Payload>,
}

/// The gravity model of `robot` (a URDF robot), with its masses as
/// `opts` says. Errors name the file and the place: a robot without a URDF,
/// a malformed `<inertial>`, links the chain carries that the other file
/// lacks, a chain that carries no mass.
pub fn gravity_model(robot: &Robot, opts: &InertiaOptions) -> Result<GravityModel> {
    let src = robot.source.as_ref().ok_or_else(|| {
        Error::Invalid(format!(
            "robot '{}' has no URDF: gravity torques need a URDF with <inertial> elements",
            robot.name
        ))
    })?;
    let (links, joints) = tree(&src.text, &src.path)?;
    let mut masses = match &opts.inertials {
        None => link_masses(&src.text, &src.path)?,
        Some((text, path)) => {
            let other = link_masses(text, path)?;
            if other.is_empty() {
                return Err(Error::Parse {
                    path: path.clone(),
                    message: "no link has an <inertial> element: a file of masses needs <inertial><mass value=…/></inertial> in the links of the chain".into(),
                });
            }
            let missing: Vec<&str> = links
                .iter()
                .filter(|l| !other.contains_key(*l))
                .map(String::as_str)
                .collect();
            if !missing.is_empty() && missing.len() == links.len() {
                return Err(Error::Parse {
                    path: path.clone(),
                    message: format!(
                        "none of the links of {} is in this file (e.g. '{}')",
                        src.path, links[0]
                    ),
                });
            }
            other
        }
    };
    masses.retain(|l, _| links.contains(l));
    let held: HashMap<String, f64> = src
        .joints
        .iter()
        .filter_map(|j| j.locked.map(|v| (j.name.clone(), v)))
        .collect();
    let mut model =
        GravityModel::new(links, joints, &masses, &src.driven_names(), &held).map_err(|e| {
            Error::Parse {
                path: src.path.clone(),
                message: e.to_string(),
            }
        })?;
    if let Some(p) = opts.payload {
        model.add_point_mass(&src.tip, p.mass, Vector3::from(p.at));
    }
    if model.carried_mass().iter().all(|&m| m == 0.0) {
        let from = opts.inertials.as_ref().map_or(&src.path, |(_, p)| p);
        return Err(Error::Parse {
            path: from.clone(),
            message: format!(
                "the chain {} → {} carries no mass: the links below its joints have no <inertial> with a mass (give one with another URDF's inertials or a payload)",
                src.base, src.tip
            ),
        });
    }
    Ok(model)
}

fn parse_doc<'a>(text: &'a str, path: &str) -> Result<roxmltree::Document<'a>> {
    let opts = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..roxmltree::ParsingOptions::default()
    };
    roxmltree::Document::parse_with_options(text, opts).map_err(|e| Error::Parse {
        path: path.to_string(),
        message: format!("not XML: {e}"),
    })
}

/// An error at a node: the file, line and column.
fn at(
    path: &str,
    doc: &roxmltree::Document<'_>,
    node: roxmltree::Node<'_, '_>,
    what: String,
) -> Error {
    let p = doc.text_pos_at(node.range().start);
    Error::Parse {
        path: path.to_string(),
        message: format!("line {}, column {}: {what}", p.row, p.col),
    }
}

fn numbers<const N: usize>(
    path: &str,
    doc: &roxmltree::Document<'_>,
    node: roxmltree::Node<'_, '_>,
    attr: &str,
    default: [f64; N],
) -> Result<[f64; N]> {
    let Some(s) = node.attribute(attr) else {
        return Ok(default);
    };
    let v: Vec<f64> = s
        .split_whitespace()
        .map(str::parse::<f64>)
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| {
            at(
                path,
                doc,
                node,
                format!("{attr}=\"{s}\" is not {N} numbers"),
            )
        })?;
    if v.len() != N || !v.iter().all(|x| x.is_finite()) {
        return Err(at(
            path,
            doc,
            node,
            format!("{attr}=\"{s}\" is not {N} finite numbers"),
        ));
    }
    let mut out = [0.0; N];
    out.copy_from_slice(&v);
    Ok(out)
}

fn child<'a, 'i>(node: roxmltree::Node<'a, 'i>, name: &str) -> Option<roxmltree::Node<'a, 'i>> {
    node.children()
        .find(|c| c.is_element() && c.tag_name().name() == name)
}

fn origin(
    path: &str,
    doc: &roxmltree::Document<'_>,
    node: roxmltree::Node<'_, '_>,
) -> Result<Isometry3<f64>> {
    let Some(o) = child(node, "origin") else {
        return Ok(Isometry3::identity());
    };
    let x = numbers(path, doc, o, "xyz", [0.0; 3])?;
    let r = numbers(path, doc, o, "rpy", [0.0; 3])?;
    Ok(Isometry3::from_parts(
        Translation3::new(x[0], x[1], x[2]),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_euler_angles(r[0], r[1], r[2])),
    ))
}

/// The URDF's links (by name) and joints.
fn tree(text: &str, path: &str) -> Result<(Vec<String>, Vec<TreeJoint>)> {
    let doc = parse_doc(text, path)?;
    let top = doc.root_element();
    let mut links: Vec<String> = top
        .children()
        .filter(|c| c.is_element() && c.tag_name().name() == "link")
        .filter_map(|c| c.attribute("name").map(str::to_string))
        .collect();
    let mut joints = Vec::new();
    for j in top
        .children()
        .filter(|c| c.is_element() && c.tag_name().name() == "joint")
    {
        let name = j.attribute("name").unwrap_or_default().to_string();
        let mut link = |tag: &str| -> Result<usize> {
            let l = child(j, tag)
                .and_then(|c| c.attribute("link"))
                .ok_or_else(|| {
                    at(
                        path,
                        &doc,
                        j,
                        format!("joint '{name}' has no <{tag} link=…>"),
                    )
                })?;
            Ok(match links.iter().position(|x| x == l) {
                Some(i) => i,
                None => {
                    links.push(l.to_string());
                    links.len() - 1
                }
            })
        };
        let (parent, child_link) = (link("parent")?, link("child")?);
        let kind = match j.attribute("type") {
            Some("revolute" | "continuous") => Some(JointKind::Revolute),
            Some("prismatic") => Some(JointKind::Prismatic),
            _ => None,
        };
        let axis = match child(j, "axis") {
            Some(a) => numbers(path, &doc, a, "xyz", [1.0, 0.0, 0.0])?,
            None => [1.0, 0.0, 0.0],
        };
        let axis = Vector3::from(axis);
        if kind.is_some() && axis.norm() == 0.0 {
            return Err(at(path, &doc, j, format!("joint '{name}' has a zero axis")));
        }
        joints.push(TreeJoint {
            name,
            parent,
            child: child_link,
            origin: origin(path, &doc, j)?,
            axis: if axis.norm() > 0.0 {
                axis.normalize()
            } else {
                axis
            },
            kind,
        });
    }
    Ok((links, joints))
}

/// Each link's `<inertial>` mass and centre of mass (links without one are
/// left out).
fn link_masses(text: &str, path: &str) -> Result<HashMap<String, LinkMass>> {
    let doc = parse_doc(text, path)?;
    let mut out = HashMap::new();
    for l in doc
        .root_element()
        .children()
        .filter(|c| c.is_element() && c.tag_name().name() == "link")
    {
        let Some(i) = child(l, "inertial") else {
            continue;
        };
        let name = l.attribute("name").unwrap_or_default();
        let m = child(i, "mass").ok_or_else(|| {
            at(
                path,
                &doc,
                i,
                format!("link '{name}': <inertial> without <mass value=…>"),
            )
        })?;
        let [mass] = numbers(path, &doc, m, "value", [f64::NAN])?;
        if !(mass >= 0.0) {
            return Err(at(
                path,
                &doc,
                m,
                format!("link '{name}': the mass must be a number >= 0 (kg)"),
            ));
        }
        let com = origin(path, &doc, i)?.translation.vector;
        out.insert(name.to_string(), LinkMass { mass, com });
    }
    Ok(out)
}
