//! The text form of a calibrated robot's frames: the measurement frame, the
//! tool or markers, and each joint's origin in URDF terms.

use crate::frames::report::{FrameBlock, FramesReport};

fn v3(v: [f64; 3], d: usize) -> String {
    format!("[{:.d$}, {:.d$}, {:.d$}]", v[0], v[1], v[2])
}

/// σ's with a not-estimated coordinate shown as `fixed` (never 0).
pub fn s3(v: [Option<f64>; 3], d: usize) -> String {
    let one = |x: Option<f64>| x.map_or_else(|| "fixed".to_string(), |x| format!("{x:.d$}"));
    format!("[{}, {}, {}]", one(v[0]), one(v[1]), one(v[2]))
}

fn frame_lines(name: &str, f: &FrameBlock) -> String {
    let mut s = format!(
        "{name} ({} → {}):\n  xyz {} m, rpy {} rad = {} deg, quaternion [w x y z] {}\n",
        f.parent,
        f.child.as_deref().unwrap_or("measured frame"),
        v3(f.xyz, 6),
        v3(f.rpy, 6),
        v3(f.rpy_deg, 4),
        format!(
            "[{:.6}, {:.6}, {:.6}, {:.6}]",
            f.quaternion[0], f.quaternion[1], f.quaternion[2], f.quaternion[3]
        )
    );
    if let (Some(x), Some(r)) = (f.sigma_xyz_mm, f.sigma_rotation_deg) {
        s += &format!(
            "  σ xyz {} mm, σ of a rotation about its x, y, z {} deg\n",
            s3(x, 3),
            s3(r, 4)
        );
    }
    s
}

/// The frames blocks of a calibration report.
pub fn frames_text(r: &FramesReport) -> String {
    let mut s = format!(
        "\ncalibrated frames of {} (chain {} → {}):\n",
        r.robot, r.chain.base, r.chain.tip
    );
    s += &frame_lines("measurement frame", &r.measurement_frame);
    if let Some(t) = &r.tool {
        s += &frame_lines("tool", t);
    }
    for m in &r.markers {
        s += &format!("{} on {}: xyz {} m", m.name, m.parent, v3(m.xyz, 6));
        if let Some(x) = m.sigma_xyz_mm {
            s += &format!(", σ {} mm", s3(x, 3));
        }
        s += "\n";
    }
    s += "joint origins: change from the file's <origin> (Δxyz in mm; Δrot, the turn about the joint frame's x, y, z, in degrees; offset, the turn about the joint's own axis, in degrees):\n";
    s += &format!(
        "{:<28} {:>30} {:>30} {:>10} {:>7}\n",
        "joint", "Δxyz (mm)", "Δrot (deg)", "offset°", "max|t|"
    );
    for j in &r.joints.0 {
        s += &format!(
            "{:<28} {:>30} {:>30} {:>10.4} {:>7}\n",
            j.name,
            v3(j.delta_xyz_mm, 3),
            v3(j.delta_rotation_deg, 4),
            j.offset_deg,
            j.max_t.map_or("-".into(), |t| format!("{t:.1}"))
        );
    }
    let held: Vec<String> = r
        .joints
        .0
        .iter()
        .filter(|j| !j.fixed.is_empty())
        .map(|j| format!("{} {}", j.name, j.fixed.join(" ")))
        .collect();
    if !held.is_empty() {
        s += &format!(
            "fixed (held at the file's value: no estimated unknown moves them, so they have no σ): {}\n",
            held.join("; ")
        );
    }
    let broken: Vec<_> = r.structure.iter().filter(|a| !a.kept).collect();
    if !broken.is_empty() {
        s += "axis relations the calibrated model no longer keeps (closed-form IK solvers assume them):\n";
        for a in broken {
            s += &format!(
                "  {} → {}: nominally {} ({:.4}°, {:.3} mm apart), now {:.4}° and {:.3} mm\n",
                a.from,
                a.to,
                a.nominal,
                a.angle_deg[0],
                a.distance_mm[0],
                a.angle_deg[1],
                a.distance_mm[1]
            );
        }
    }
    s
}
