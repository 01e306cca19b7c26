//! `index.html` of a report folder: one self-contained page (no network, no
//! sibling file read) showing the robot at each chosen pose in visiting
//! order, the planned moves between them animated, the scene (floor,
//! obstacles), the sensor's placement, a fit's measured and fitted points
//! and the report's figures and tables. three.js is embedded at build time
//! ([`assets`]); link placements are computed here, by activecal's own
//! kinematics ([`links`]), so the page draws exactly the model activecal
//! uses; the page's script only poses the meshes it is given.
//!
//! The page keeps a read-out for tests and scripts: `<pre id="readout">`
//! (JSON: poses, links, triangles, the pose shown and the world matrices
//! of its links), and opens at pose k with the URL hash `#pose=k`.

pub mod assets;
pub mod encode;
mod html;
pub(crate) mod links;
pub mod meshes;

pub use html::{figure, table};

use crate::collision::{Closest, CollisionModel, Obstacle};
use crate::error::Result;
use crate::io::atomic::write_atomic;
use crate::model::{ParamTable, Robot};
use links::LinkPlacer;
use meshes::{MeshData, Visual};
use nalgebra::Isometry3;
use serde::Serialize;
use std::path::Path;

/// Largest joint travel between two samples of an animated move (radians,
/// or metres for a prismatic joint).
pub const MOVE_STEP: f64 = 0.1;
/// Most samples of one straight move.
pub const MOVE_SAMPLES_MAX: usize = 16;

/// One pose as the page shows it.
#[derive(Clone, Debug, Serialize)]
pub struct PoseView {
    /// Its label in the list.
    pub label: String,
    /// Joint values (radians or metres).
    pub q: Vec<f64>,
    /// Each link's placement (column-major 4×4, base link frame).
    pub links: Vec<[f64; 16]>,
    /// With a fit: each link's placement in the calibrated model.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub calibrated: Option<Vec<[f64; 16]>>,
    /// With a fit: the measured point (base link frame, metres).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measured: Option<[f64; 3]>,
    /// With a fit: the calibrated model's point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fitted: Option<[f64; 3]>,
    /// A mark ("flagged", "held out"), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mark: Option<String>,
    /// With a collision filter: the least clearance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clearance: Option<ClearanceView>,
}

/// The least clearance of a pose or a move: the closest pair of the
/// collision filter's checked pairs.
#[derive(Clone, Debug, Serialize)]
pub struct ClearanceView {
    /// The two links, or the link and the obstacle (`box 1`, `floor`).
    pub between: [String; 2],
    /// The page's links among them (indices into [`Page::links`]).
    pub links: Vec<usize>,
    /// Their least distance, metres (0: touching).
    pub distance: f64,
}

/// A planned move, sampled.
#[derive(Clone, Debug, Serialize)]
pub struct MoveView {
    /// Pose it starts from (`None`: home).
    pub from: Option<usize>,
    /// Pose it goes to.
    pub to: usize,
    /// Whether it goes through a via configuration.
    pub via: bool,
    /// Samples along it.
    pub samples: usize,
    /// Link placements per sample: `samples × links × 12` little-endian
    /// f32 (the top three rows of the column-major 4×4, column by
    /// column), base64.
    pub frames: String,
    /// With a collision filter: the least clearance over the samples.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clearance: Option<ClearanceView>,
    /// Joint values of the samples.
    #[serde(skip)]
    pub qs: Vec<Vec<f64>>,
}

/// The sensor's placement.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SensorView {
    /// A tracker (or any point sensor) at a point of the base frame.
    Tracker {
        /// Its position (metres, base link frame).
        position: [f64; 3],
    },
    /// A camera: its placement per pose (on the robot, or fixed), the
    /// board's corners per pose, and its field of view.
    Camera {
        /// Camera placement per pose (column-major 4×4; z the optical axis).
        placements: Vec<[f64; 16]>,
        /// The board's outline per pose (corners, base link frame).
        boards: Vec<Vec<[f64; 3]>>,
        /// Horizontal and vertical field of view (radians).
        fov: [f64; 2],
        /// The lines of sight checked per pose (empty when none was).
        #[serde(skip_serializing_if = "Vec::is_empty")]
        rays: Vec<Vec<RayView>>,
    },
    /// A contact design or fit: the sockets the tool touches and the
    /// planes it touches.
    Contacts {
        /// The sockets (points), in the page's frame.
        sockets: Vec<SocketView>,
        /// The planes, each as a square about its contacts.
        planes: Vec<PlaneView>,
    },
}

/// A line of sight the library checked: from the camera to one of the
/// board's points (page frame, metres), and whether it held.
#[derive(Clone, Debug, Serialize)]
pub struct RayView {
    /// The camera's centre.
    pub from: [f64; 3],
    /// The board's point.
    pub to: [f64; 3],
    /// Whether nothing of the robot blocks it.
    pub clear: bool,
}

/// A socket of a contact design: its name and place (page frame, metres).
#[derive(Clone, Debug, Serialize)]
pub struct SocketView {
    /// Its name.
    pub name: String,
    /// Its centre.
    pub position: [f64; 3],
}

/// A plane of a contact design, drawn as a translucent square.
#[derive(Clone, Debug, Serialize)]
pub struct PlaneView {
    /// Its name.
    pub name: String,
    /// The square's corners in order (page frame, metres).
    pub corners: [[f64; 3]; 4],
}

/// Everything the page shows.
#[derive(Clone, Debug, Serialize)]
pub struct Page {
    /// The page's title.
    pub title: String,
    /// The robot's name.
    pub robot: String,
    /// Link names.
    pub links: Vec<String>,
    /// Each link's parent link (index), `None` for the root.
    pub parents: Vec<Option<usize>>,
    /// Whether the links are a URDF's (else the model's frames).
    pub urdf: bool,
    /// Visual elements.
    pub visuals: Vec<Visual>,
    /// Meshes they use.
    pub meshes: Vec<MeshData>,
    /// The poses in visiting order.
    pub poses: Vec<PoseView>,
    /// The moves between them.
    pub moves: Vec<MoveView>,
    /// The floor's height (base frame), if any.
    pub floor: Option<f64>,
    /// Obstacles (base frame).
    pub obstacles: Vec<Obstacle>,
    /// The sensor.
    pub sensor: Option<SensorView>,
    /// Magnification of the residuals (fitted point → measured point).
    pub magnify: Option<f64>,
    /// Magnification of the calibrated robot's difference from the nominal.
    pub magnify_robot: Option<f64>,
    /// What was not drawn, or drawn simplified.
    pub notes: Vec<String>,
    /// Figures (caption, PNG bytes).
    #[serde(skip)]
    pub figures: Vec<(String, Vec<u8>)>,
    /// Tables and text (HTML).
    #[serde(skip)]
    pub sections: Vec<String>,
    #[serde(skip)]
    placer: Option<std::sync::Arc<LinkPlacer>>,
}

/// Column-major entries of an isometry's 4×4 matrix (three.js's order).
#[must_use]
pub fn column_major(m: &Isometry3<f64>) -> [f64; 16] {
    let h = m.to_homogeneous();
    let mut out = [0.0; 16];
    out.copy_from_slice(h.as_slice());
    out
}

impl Page {
    /// A page for `robot`: its links and their visuals (meshes found as
    /// `package_dirs` and the URDF's directory say).
    #[must_use]
    pub fn new(title: &str, robot: &Robot, package_dirs: &[String]) -> Self {
        let mut notes = Vec::new();
        let parsed = robot.source.as_deref().and_then(|s| {
            urdf_rs::read_from_string(&s.text)
                .map_err(|e| notes.push(format!("the URDF's visuals are not drawn: {e}")))
                .ok()
                .map(|u| {
                    (
                        u,
                        Path::new(&s.path)
                            .parent()
                            .map(Path::to_path_buf)
                            .unwrap_or_default(),
                    )
                })
        });
        let placer = LinkPlacer::new(robot, parsed.as_ref().map(|p| &p.0));
        let (visuals, meshes) = match (&parsed, placer.is_urdf()) {
            (Some((u, dir)), true) => {
                let (v, m, n) = meshes::visuals(u, &placer.names, dir, package_dirs);
                notes.extend(n);
                (v, m)
            }
            _ => (Vec::new(), Vec::new()),
        };
        if !placer.is_urdf() {
            notes.push("no URDF: the robot is drawn as its model's joint frames".into());
        }
        Self {
            title: title.to_string(),
            robot: robot.name.clone(),
            links: placer.names.clone(),
            parents: placer.parents(),
            urdf: placer.is_urdf(),
            visuals,
            meshes,
            poses: Vec::new(),
            moves: Vec::new(),
            floor: None,
            obstacles: Vec::new(),
            sensor: None,
            magnify: None,
            magnify_robot: None,
            notes,
            figures: Vec::new(),
            sections: Vec::new(),
            placer: Some(std::sync::Arc::new(placer)),
        }
    }

    fn placer(&self) -> &LinkPlacer {
        self.placer.as_deref().expect("Page::new sets the placer")
    }

    /// Each link's placement at `q` with `table` (base link frame).
    #[must_use]
    pub fn place(&self, robot: &Robot, table: &ParamTable, q: &[f64]) -> Vec<Isometry3<f64>> {
        self.placer().place(robot, table, q)
    }

    /// As [`Page::place`], the base link at `mount` in the measurement frame.
    #[must_use]
    pub fn place_mounted(
        &self,
        robot: &Robot,
        table: &ParamTable,
        q: &[f64],
        mount: Isometry3<f64>,
    ) -> Vec<Isometry3<f64>> {
        self.placer().place_mounted(robot, table, q, mount)
    }

    /// From the measurement frame (the base link at `mount` in it) to the
    /// page's frame at joint values `q`.
    #[must_use]
    pub fn measurement_to_page(&self, q: &[f64], mount: Isometry3<f64>) -> Isometry3<f64> {
        self.placer().measurement_to_page(q, mount)
    }

    /// The base link's pose in the measurement frame (identity without a
    /// URDF).
    #[must_use]
    pub fn mount(&self) -> Isometry3<f64> {
        self.placer().mount()
    }

    /// Adds poses (labels and joint values) at `table`.
    pub fn add_poses(&mut self, robot: &Robot, table: &ParamTable, poses: &[(String, Vec<f64>)]) {
        for (label, q) in poses {
            let links = self
                .place(robot, table, q)
                .iter()
                .map(column_major)
                .collect();
            self.poses.push(PoseView {
                label: label.clone(),
                q: q.clone(),
                links,
                calibrated: None,
                measured: None,
                fitted: None,
                mark: None,
                clearance: None,
            });
        }
    }

    /// Adds the straight joint-space moves of a tour through the poses
    /// added (from `home` when given), through `vias` (`(from, to, q)`,
    /// `from` `None` for home) where the tour takes one.
    pub fn add_moves(
        &mut self,
        robot: &Robot,
        table: &ParamTable,
        home: Option<&[f64]>,
        vias: &[(Option<usize>, usize, Vec<f64>)],
    ) {
        let qs: Vec<Vec<f64>> = self.poses.iter().map(|p| p.q.clone()).collect();
        let mut moves = Vec::new();
        let pairs: Vec<(Option<usize>, Vec<f64>, usize)> = match home {
            Some(h) if !qs.is_empty() => std::iter::once((None, h.to_vec(), 0))
                .chain((1..qs.len()).map(|k| (Some(k - 1), qs[k - 1].clone(), k)))
                .collect(),
            _ => (1..qs.len())
                .map(|k| (Some(k - 1), qs[k - 1].clone(), k))
                .collect(),
        };
        for (from, a, to) in pairs {
            let via = vias
                .iter()
                .find(|v| v.0 == from && v.1 == to)
                .map(|v| v.2.clone());
            let mut path = vec![a];
            path.extend(via.iter().cloned());
            path.push(qs[to].clone());
            let mut bytes = Vec::new();
            let mut samples = 0;
            let mut sampled = Vec::new();
            for (k, w) in path.windows(2).enumerate() {
                let travel = w[0]
                    .iter()
                    .zip(&w[1])
                    .map(|(x, y)| (y - x).abs())
                    .fold(0.0, f64::max);
                let n = ((travel / MOVE_STEP).ceil() as usize).clamp(2, MOVE_SAMPLES_MAX);
                for s in usize::from(k > 0)..=n {
                    let t = s as f64 / n as f64;
                    let q: Vec<f64> = w[0]
                        .iter()
                        .zip(&w[1])
                        .map(|(x, y)| x + t * (y - x))
                        .collect();
                    for m in self.place(robot, table, &q) {
                        let c = column_major(&m);
                        let top = c.chunks_exact(4).flat_map(|col| &col[..3]);
                        bytes.extend(top.flat_map(|v| (*v as f32).to_le_bytes()));
                    }
                    sampled.push(q);
                    samples += 1;
                }
            }
            moves.push(MoveView {
                from,
                to,
                via: via.is_some(),
                samples,
                frames: encode::base64(&bytes),
                clearance: None,
                qs: sampled,
            });
        }
        self.moves = moves;
    }

    /// The least clearance of each pose and of each move (over the move's
    /// samples, [`MOVE_STEP`] apart in every joint) by `model`
    /// ([`CollisionModel::closest`]).
    pub fn add_clearances(&mut self, model: &CollisionModel) {
        let view = |c: Closest, names: &[String]| {
            let between = [c.pair.link, c.pair.other];
            let links = between
                .iter()
                .filter_map(|n| names.iter().position(|m| m == n))
                .collect();
            ClearanceView {
                between,
                links,
                distance: c.distance,
            }
        };
        for p in &mut self.poses {
            p.clearance = model.closest(&p.q).map(|c| view(c, &self.links));
        }
        for m in &mut self.moves {
            let least =
                m.qs.iter()
                    .filter_map(|q| model.closest(q))
                    .min_by(|a, b| a.distance.total_cmp(&b.distance));
            m.clearance = least.map(|c| view(c, &self.links));
        }
    }

    /// The page's HTML text (deterministic: no time, no random).
    pub fn html(&self) -> Result<String> {
        html::page(self)
    }

    /// Writes the page as `index.html` into `dir` (atomically).
    pub fn write(&self, dir: &Path) -> Result<()> {
        write_atomic(&dir.join("index.html"), self.html()?.as_bytes())?;
        Ok(())
    }
}
