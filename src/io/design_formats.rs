//! A design in the robot's terms: the formats `select --out` writes, told
//! apart by the extension.
//!
//! * `.json`: the design file ([`DesignFile`]), with the joint names.
//! * `.csv`: a header of the joint names and `id`, one pose a row, in
//!   visiting order (what `--pool file:` and `--existing` read back); a via
//!   configuration of the tour is a row whose id is `via`, before the pose
//!   it leads to (the readers skip it).
//! * `.yaml`: the design file's keys (robot, pool, ids, ...) with the joint
//!   values as a list of named joint configurations,
//!   `configurations: [{name: pose_01, id: 17, joints: {joint_a: 0.1, ...}}]`
//!   (a via configuration of the tour as `{name: via_01_02, via: true,
//!   joints: ...}` before the pose it leads to),
//!   the shape robot scripts and ROS tools read (a name and a map of joint
//!   name to position). [`DesignFile::read`] loads it as it loads JSON
//!   ([`DesignFile::parse_yaml`]).
//!
//! YAML is written and read with `serde-saphyr` (pure Rust, maintained;
//! `serde_yaml` is archived and its fork `serde_yml` unsound). Values are
//! written with the shortest text that reads back as the same `f64`.

use super::design::DesignFile;
use crate::error::{Error, Result};
use serde::Serialize;
use std::path::Path;

/// The formats of a design output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DesignFormat {
    /// The design file, JSON.
    Json,
    /// Joint values with a header of names, one pose a row.
    Csv,
    /// The design with named joint configurations.
    Yaml,
}

impl DesignFormat {
    /// The format of `path` by its extension (`.json`, `.csv`, `.yaml` or
    /// `.yml`); any other is an error naming the three.
    pub fn of(path: &Path) -> Result<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("json") => Ok(Self::Json),
            Some("csv") => Ok(Self::Csv),
            Some("yaml" | "yml") => Ok(Self::Yaml),
            _ => Err(Error::Invalid(format!(
                "{}: a design is written as .json (the design file), .csv (joint values, one pose a row) or .yaml (named joint configurations); name the file with one of these extensions",
                path.display()
            ))),
        }
    }
}

/// Writes `d` to `path` in the format of its extension ([`DesignFormat`]):
/// what `select --out` writes. An existing file is only replaced when
/// `overwrite` is set.
pub fn write(d: &DesignFile, path: &Path, overwrite: bool) -> Result<()> {
    let format = DesignFormat::of(path)?;
    let text = match format {
        DesignFormat::Json => return d.write(path, overwrite),
        DesignFormat::Csv => to_csv(d)?,
        DesignFormat::Yaml => to_yaml(d)?,
    };
    super::design::write_design_text(path, &text, overwrite)
}

/// Joint values keyed by joint name, in the chain's order (the YAML form of
/// a configuration, shared by every design written as named joints).
pub(crate) struct Joints<'a> {
    /// The joints' names.
    pub(crate) names: &'a [String],
    /// Their values, in the same order.
    pub(crate) q: &'a [f64],
}

impl Serialize for Joints<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(Some(self.names.len()))?;
        for (n, v) in self.names.iter().zip(self.q) {
            m.serialize_entry(n, v)?;
        }
        m.end()
    }
}

/// One named joint configuration of the YAML form: a pose (with its id)
/// or a via configuration of the tour (`via: true`, no id).
#[derive(Serialize)]
struct Named<'a> {
    name: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    id: Option<usize>,
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    via: bool,
    joints: Joints<'a>,
}

/// The design's configurations in visiting order, each via configuration
/// just before the pose it leads to: `(name, id or None for a via, q)`.
fn visiting(d: &DesignFile) -> Vec<(String, Option<usize>, &[f64])> {
    let qs = d.q.as_deref().unwrap_or_default();
    let width = qs.len().to_string().len().max(2);
    let mut out = Vec::with_capacity(qs.len() + d.via.len());
    for (k, (q, &id)) in qs.iter().zip(&d.poses).enumerate() {
        for v in d.via.iter().filter(|v| v.to == k) {
            let from = v
                .from
                .map_or("home".to_string(), |f| format!("{:0width$}", f + 1));
            out.push((
                format!("via_{from}_{:0width$}", k + 1),
                None,
                v.q.as_slice(),
            ));
        }
        out.push((format!("pose_{:0width$}", k + 1), Some(id), q.as_slice()));
    }
    out
}

/// The design's joint names: stored, else an error (a design written
/// before joint names were stored cannot name its joints).
fn names_of(d: &DesignFile) -> Result<&[String]> {
    d.joint_names
        .as_deref()
        .ok_or_else(|| Error::Invalid("the design stores no joint names ('joint_names')".into()))
}

/// The design as CSV: joint names and `id`, one pose a row, in the design's
/// order.
pub fn to_csv(d: &DesignFile) -> Result<String> {
    let names = names_of(d)?;
    if d.via.is_empty() {
        let qs = d.q.as_deref().unwrap_or_default();
        return Ok(crate::pool::summary::poses_csv(names, qs, &d.poses));
    }
    // A via configuration is a row whose id is `via` (the readers of
    // `--pool file:` skip it).
    let mut s = names.join(",") + ",id\n";
    for (_, id, q) in visiting(d) {
        for v in q {
            s += &format!("{v:?},");
        }
        s += &id.map_or(crate::pool::file::VIA_ID.to_string(), |i| i.to_string());
        s += "\n";
    }
    Ok(s)
}

/// The design as YAML (see the module docs).
pub fn to_yaml(d: &DesignFile) -> Result<String> {
    let names = names_of(d)?;
    let configurations: Vec<Named<'_>> = visiting(d)
        .into_iter()
        .map(|(name, id, q)| Named {
            name,
            id,
            via: id.is_none(),
            joints: Joints { names, q },
        })
        .collect();
    let mut rest = d.clone();
    rest.q = None;
    rest.via = Vec::new();
    #[derive(Serialize)]
    struct Doc<'a> {
        #[serde(flatten)]
        design: &'a DesignFile,
        configurations: Vec<Named<'a>>,
    }
    serde_saphyr::to_string(&Doc {
        design: &rest,
        configurations,
    })
    .map_err(|e| Error::Invalid(format!("writing YAML: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Robot;
    use crate::pool::{Pool, PoolSource, PoolSpec};

    /// 100 random poses of `r` (seed 2).
    fn random_pool(r: &Robot) -> Pool {
        PoolSpec::of(PoolSource::Random {
            count: 100,
            seed: 2,
        })
        .build(r, &r.nominal)
        .unwrap()
    }

    #[test]
    fn formats_are_told_by_extension() {
        assert_eq!(
            DesignFormat::of(Path::new("a.JSON")).unwrap(),
            DesignFormat::Json
        );
        assert_eq!(
            DesignFormat::of(Path::new("a.csv")).unwrap(),
            DesignFormat::Csv
        );
        assert_eq!(
            DesignFormat::of(Path::new("a.yml")).unwrap(),
            DesignFormat::Yaml
        );
        let e = DesignFormat::of(Path::new("a.txt"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(".json") && e.contains(".csv") && e.contains(".yaml"),
            "{e}"
        );
    }

    #[test]
    fn yaml_round_trips_every_value_exactly() {
        let r = Robot::puma560();
        let pool = random_pool(&r);
        let d = DesignFile::from_pool(&r, &pool, &[4, 50, 9]);
        let text = to_yaml(&d).unwrap();
        assert!(
            text.contains("configurations:") && text.contains("pose_01"),
            "{text}"
        );
        let back = DesignFile::parse_yaml(&text, "d.yaml").unwrap();
        assert_eq!(back.q, d.q);
        assert_eq!(back.poses, d.poses);
        assert_eq!(back.joint_names, d.joint_names);
        assert_eq!(
            serde_json::to_value(back.spec().unwrap()).unwrap(),
            serde_json::to_value(d.spec().unwrap()).unwrap()
        );
        // A configuration without one joint is refused, naming it.
        let name = &d.joint_names.as_ref().unwrap()[2];
        let cut: String = text
            .lines()
            .filter(|l| {
                let key = l.trim_start().replace(['"', '\''], "");
                !key.starts_with(&format!("{name}:"))
            })
            .map(|l| format!("{l}\n"))
            .collect();
        let e = DesignFile::parse_yaml(&cut, "d.yaml")
            .unwrap_err()
            .to_string();
        assert!(e.contains(name.as_str()) && e.contains("d.yaml"), "{e}");
    }

    #[test]
    fn via_configurations_are_written_in_visiting_order_and_skipped_on_reading() {
        let r = Robot::puma560();
        let pool = random_pool(&r);
        let mut d = DesignFile::from_pool(&r, &pool, &[4, 50, 9]);
        let via = vec![0.25; r.dof()];
        d.via = vec![crate::io::design::ViaPoint {
            from: Some(0),
            to: 1,
            q: via.clone(),
        }];
        // YAML: the via between pose_01 and pose_02, marked, without an id;
        // read back, only the poses.
        let text = to_yaml(&d).unwrap();
        let (a, v, b) = (
            text.find("pose_01").unwrap(),
            text.find("via_01_02").unwrap(),
            text.find("pose_02").unwrap(),
        );
        assert!(a < v && v < b, "{text}");
        assert!(text.contains("via: true"), "{text}");
        let back = DesignFile::parse_yaml(&text, "d.yaml").unwrap();
        assert_eq!((back.poses, back.q), (d.poses.clone(), d.q.clone()));
        // CSV: the via is the second row, id `via`; the pool reader skips
        // it and says so.
        let csv = to_csv(&d).unwrap();
        let rows: Vec<&str> = csv.lines().collect();
        assert_eq!(rows.len(), 5, "{csv}");
        assert!(
            rows[2].ends_with(",via") && rows[2].starts_with("0.25,"),
            "{csv}"
        );
        let c = crate::pool::file::parse_csv(Path::new("d.csv"), &csv, &r).unwrap();
        assert_eq!(Some(c.qs), d.q);
        assert!(c.notes.iter().any(|n| n.contains("1 via")), "{:?}", c.notes);
    }

    #[test]
    fn csv_lists_names_and_ids() {
        let r = Robot::puma560();
        let pool = Pool::full(&r, 3).unwrap();
        let d = DesignFile::from_pool(&r, &pool, &[7, 3]);
        let text = to_csv(&d).unwrap();
        let mut lines = text.lines();
        assert!(lines.next().unwrap().ends_with(",id"));
        assert!(lines.next().unwrap().ends_with(",7"));
    }
}
