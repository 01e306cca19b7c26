//! The serial arms of `example-robot-data` (PyPI package 6.0.0, pinned in
//! `verify/requirements.txt`; URDFs under
//! `<site-packages>/cmeel.prefix/share/example-robot-data/robots/`), as data:
//! for each, the URDF, the chain's base and tip links, any locked joints, and
//! the moving joints the chain must have — chosen by reading the URDFs, not
//! by trying activecal. `verify/tests/live_erd.rs` imports every arm with
//! activecal and compares its forward kinematics with Pinocchio's on the
//! same file; `tests/erd_fixtures.rs` (root crate, no Python) compares it with
//! the fixtures `fixtures/example-robot-data/fk/<arm>.json`.
//!
//! This file is pure data with no dependencies, so that the root crate's
//! test includes it (`#[path]`) and reads the same table.
//!
//! # What is an arm
//!
//! A chain of at least 4 revolute, continuous or prismatic joints from the
//! URDF's root or the link an arm is mounted on to an end-effector, flange or
//! tool link. The choices:
//!
//! * **Fixed-base arms** (Panda, Kinova Jaco, xArm7, Z1, SO-100/101, the UR
//!   arms, the hexarotor's 5-joint arm) and arms fixed on a robot body
//!   through fixed joints only (Baxter's two arms on its torso, the Jaco on
//!   ANYmal, the Z1 on the B1): from the URDF's root (the default base) to
//!   the flange or tool frame the upstream description names for it
//!   (`tool0` on the UR arms, `panda_hand_tcp`, `j2s6s200_end_effector`,
//!   `left_gripper`, `link_eef`, …). Where the arm ends in a gripper joint
//!   (Z1, SO-100), at the link that joint hangs from: the gripper's jaw is
//!   not part of the arm.
//! * **Arms on a moving torso** (TIAGo, TIAGo++, TIAGo Pro, PR2, Talos,
//!   Centauro, Alex, G1, the human model, iCub, Romeo, the simple humanoid):
//!   from the link the shoulder joint is mounted on (`torso_lift_link`,
//!   `torso_2_link`, `chest`, …) to the hand's flange or tool frame; the
//!   lift, waist, spine or trunk joints below the shoulder are not the arm's.
//!   TIAGo, PR2 and Talos also appear with their torso joints, from the root
//!   (the TIAGo commands of the README do this), one with joints locked.
//! * Legs of quadrupeds, bipeds and humanoids and the fingers of hands are
//!   not arms (see [`NOT_ARMS`] for the URDFs that have no arm at all).
//!
//! Each URDF of the package is either the file of some arm or listed in
//! [`NOT_ARMS`] with the reason; the live check enumerates the installed
//! package and fails on a file in neither.

/// The `example-robot-data` release the table was read from.
pub const ERD_VERSION: &str = "6.0.0";

/// What importing the arm's URDF from the same base without naming a tip
/// does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tipless {
    /// The URDF below the base is a single chain ending at the tip: the same
    /// chain is imported.
    SameChain,
    /// It branches (a tree): refused, with the candidate tips listed.
    Tree,
    /// A single chain whose last moving joint (named) drives a gripper:
    /// refused, naming that joint.
    Gripper(&'static str),
}

/// How plain `cargo test` (no Python) covers an arm.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coverage {
    /// By its own fixture, `fixtures/example-robot-data/fk/<name>.json`, and
    /// a copy of its URDF in `fixtures/example-robot-data/`.
    Fixture,
    /// By the named arm's fixture: the chain is the same transform for
    /// transform (joint origins, axes and types; names and limits may
    /// differ), which the live check confirms with Pinocchio on both files.
    SameChainAs(&'static str),
    /// Only by the live check, for the reason given.
    LiveOnly(&'static str),
}

/// One serial arm of a URDF.
#[derive(Clone, Copy, Debug)]
pub struct Arm {
    /// A unique name (the fixture's file stem).
    pub name: &'static str,
    /// The URDF, relative to the package's `robots/` directory.
    pub urdf: &'static str,
    /// The base link (`None`: the URDF's root).
    pub base: Option<&'static str>,
    /// The tip link.
    pub tip: &'static str,
    /// Joints locked at a value (radians or metres).
    pub lock: &'static [(&'static str, f64)],
    /// The chain's moving joints from base to tip, locked ones excluded.
    pub joints: &'static [&'static str],
    /// Import without a tip.
    pub tipless: Tipless,
    /// Coverage by plain `cargo test`.
    pub coverage: Coverage,
}

impl Arm {
    /// The file name of the URDF's copy in `fixtures/example-robot-data/`
    /// (the upstream file name), for arms with their own fixture.
    #[must_use]
    pub fn fixture_urdf(&self) -> Option<&'static str> {
        match self.coverage {
            Coverage::Fixture => self.urdf.rsplit('/').next(),
            _ => None,
        }
    }

    /// The arm named `name`.
    #[must_use]
    pub fn by_name(name: &str) -> Option<&'static Arm> {
        ARMS.iter().find(|a| a.name == name)
    }
}

/// PAL Robotics' TIAGo and Talos URDFs carry this notice.
const PAL_NC_ND: &str =
    "the URDF carries PAL Robotics' CC BY-NC-ND 3.0 notice: not copied into the repository";
/// Alex's descriptions are under CC BY-NC-ND 4.0.
const ALEX_NC_ND: &str =
    "Alex's descriptions are under CC BY-NC-ND 4.0: not copied into the repository";
/// TIAGo Pro's URDF is Apache-2.0 but large.
const TIAGO_PRO_SIZE: &str =
    "tiago_pro.urdf is 109 KB: the fixtures keep PR2 for the dual-arm mobile manipulators";

/// The arms, in the order of the package's directories (one field per
/// line, a chain's joints on one line: a table to read, not reformatted).
#[rustfmt::skip]
pub const ARMS: &[Arm] = &[
    Arm {
        name: "panda",
        urdf: "panda_description/urdf/panda.urdf",
        base: None,
        tip: "panda_hand_tcp",
        lock: &[],
        joints: &["panda_joint1", "panda_joint2", "panda_joint3", "panda_joint4", "panda_joint5", "panda_joint6", "panda_joint7"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "panda_collision",
        urdf: "panda_description/urdf/panda_collision.urdf",
        base: None,
        tip: "panda_hand_tcp",
        lock: &[],
        joints: &["panda_joint1", "panda_joint2", "panda_joint3", "panda_joint4", "panda_joint5", "panda_joint6", "panda_joint7"],
        tipless: Tipless::Tree,
        coverage: Coverage::SameChainAs("panda"),
    },
    Arm {
        name: "kinova",
        urdf: "kinova_description/robots/kinova.urdf",
        base: None,
        tip: "j2s6s200_end_effector",
        lock: &[],
        joints: &["j2s6s200_joint_1", "j2s6s200_joint_2", "j2s6s200_joint_3", "j2s6s200_joint_4", "j2s6s200_joint_5", "j2s6s200_joint_6"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "anymal_kinova",
        urdf: "anymal_b_simple_description/robots/anymal-kinova.urdf",
        base: None,
        tip: "j2s6s200_end_effector",
        lock: &[],
        joints: &["j2s6s200_joint_1", "j2s6s200_joint_2", "j2s6s200_joint_3", "j2s6s200_joint_4", "j2s6s200_joint_5", "j2s6s200_joint_6"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "b1_z1",
        urdf: "b1_description/urdf/b1-z1.urdf",
        base: None,
        tip: "gripperStator",
        lock: &[],
        joints: &["joint1", "joint2", "joint3", "joint4", "joint5", "joint6"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "z1",
        urdf: "z1_description/urdf/z1.urdf",
        base: None,
        tip: "gripperStator",
        lock: &[],
        joints: &["joint1", "joint2", "joint3", "joint4", "joint5", "joint6"],
        tipless: Tipless::Gripper("jointGripper"),
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "so100",
        urdf: "so_arm_description/urdf/so100.urdf",
        base: None,
        tip: "gripper",
        lock: &[],
        joints: &["shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll"],
        tipless: Tipless::Gripper("gripper"),
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "so101",
        urdf: "so_arm_description/urdf/so101.urdf",
        base: None,
        tip: "gripper_frame_link",
        lock: &[],
        joints: &["shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "xarm7",
        urdf: "xarm_description/urdf/xarm7.urdf",
        base: None,
        tip: "link_eef",
        lock: &[],
        joints: &["joint1", "joint2", "joint3", "joint4", "joint5", "joint6", "joint7"],
        tipless: Tipless::SameChain,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "hextilt_flying_arm_5",
        urdf: "hextilt_description/urdf/hextilt_flying_arm_5.urdf",
        base: None,
        tip: "flying_arm_5__gripper",
        lock: &[],
        joints: &["flying_arm_5__j_base_link_link_1", "flying_arm_5__j_link_1_link_2", "flying_arm_5__j_link_2_link_3", "flying_arm_5__j_link_3_link_4", "flying_arm_5__j_link_4_link_5"],
        tipless: Tipless::SameChain,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "ur3_robot",
        urdf: "ur_description/urdf/ur3_robot.urdf",
        base: None,
        tip: "tool0",
        lock: &[],
        joints: &["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "ur3_joint_limited_robot",
        urdf: "ur_description/urdf/ur3_joint_limited_robot.urdf",
        base: None,
        tip: "tool0",
        lock: &[],
        joints: &["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::SameChainAs("ur3_robot"),
    },
    Arm {
        name: "ur3_gripper",
        urdf: "ur_description/urdf/ur3_gripper.urdf",
        base: None,
        tip: "tool0",
        lock: &[],
        joints: &["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "ur5_robot",
        urdf: "ur_description/urdf/ur5_robot.urdf",
        base: None,
        tip: "tool0",
        lock: &[],
        joints: &["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "ur5_joint_limited_robot",
        urdf: "ur_description/urdf/ur5_joint_limited_robot.urdf",
        base: None,
        tip: "tool0",
        lock: &[],
        joints: &["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::SameChainAs("ur5_robot"),
    },
    Arm {
        name: "ur5_gripper",
        urdf: "ur_description/urdf/ur5_gripper.urdf",
        base: None,
        tip: "tool0",
        lock: &[],
        joints: &["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "ur10_robot",
        urdf: "ur_description/urdf/ur10_robot.urdf",
        base: None,
        tip: "tool0",
        lock: &[],
        joints: &["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "ur10_joint_limited_robot",
        urdf: "ur_description/urdf/ur10_joint_limited_robot.urdf",
        base: None,
        tip: "tool0",
        lock: &[],
        joints: &["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::SameChainAs("ur10_robot"),
    },
    Arm {
        name: "baxter_left",
        urdf: "baxter_description/urdf/baxter.urdf",
        base: None,
        tip: "left_gripper",
        lock: &[],
        joints: &["left_s0", "left_s1", "left_e0", "left_e1", "left_w0", "left_w1", "left_w2"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "baxter_right",
        urdf: "baxter_description/urdf/baxter.urdf",
        base: None,
        tip: "right_gripper",
        lock: &[],
        joints: &["right_s0", "right_s1", "right_e0", "right_e1", "right_w0", "right_w1", "right_w2"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "tiago",
        urdf: "tiago_description/robots/tiago.urdf",
        base: Some("torso_lift_link"),
        tip: "arm_tool_link",
        lock: &[],
        joints: &["arm_1_joint", "arm_2_joint", "arm_3_joint", "arm_4_joint", "arm_5_joint", "arm_6_joint", "arm_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "tiago_torso",
        urdf: "tiago_description/robots/tiago.urdf",
        base: None,
        tip: "arm_tool_link",
        lock: &[],
        joints: &["torso_lift_joint", "arm_1_joint", "arm_2_joint", "arm_3_joint", "arm_4_joint", "arm_5_joint", "arm_6_joint", "arm_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "tiago_torso_locked",
        urdf: "tiago_description/robots/tiago.urdf",
        base: None,
        tip: "arm_tool_link",
        lock: &[("torso_lift_joint", 0.15)],
        joints: &["arm_1_joint", "arm_2_joint", "arm_3_joint", "arm_4_joint", "arm_5_joint", "arm_6_joint", "arm_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "tiago_no_hand",
        urdf: "tiago_description/robots/tiago_no_hand.urdf",
        base: Some("torso_lift_link"),
        tip: "arm_tool_link",
        lock: &[],
        joints: &["arm_1_joint", "arm_2_joint", "arm_3_joint", "arm_4_joint", "arm_5_joint", "arm_6_joint", "arm_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "tiago_dual_left",
        urdf: "tiago_description/robots/tiago_dual.urdf",
        base: Some("torso_lift_link"),
        tip: "arm_left_tool_link",
        lock: &[],
        joints: &["arm_left_1_joint", "arm_left_2_joint", "arm_left_3_joint", "arm_left_4_joint", "arm_left_5_joint", "arm_left_6_joint", "arm_left_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "tiago_dual_right",
        urdf: "tiago_description/robots/tiago_dual.urdf",
        base: Some("torso_lift_link"),
        tip: "arm_right_tool_link",
        lock: &[],
        joints: &["arm_right_1_joint", "arm_right_2_joint", "arm_right_3_joint", "arm_right_4_joint", "arm_right_5_joint", "arm_right_6_joint", "arm_right_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "tiago_pro_left",
        urdf: "tiago_pro_description/robots/tiago_pro.urdf",
        base: Some("torso_lift_link"),
        tip: "arm_left_tool_link",
        lock: &[],
        joints: &["arm_left_1_joint", "arm_left_2_joint", "arm_left_3_joint", "arm_left_4_joint", "arm_left_5_joint", "arm_left_6_joint", "arm_left_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(TIAGO_PRO_SIZE),
    },
    Arm {
        name: "tiago_pro_right",
        urdf: "tiago_pro_description/robots/tiago_pro.urdf",
        base: Some("torso_lift_link"),
        tip: "arm_right_tool_link",
        lock: &[],
        joints: &["arm_right_1_joint", "arm_right_2_joint", "arm_right_3_joint", "arm_right_4_joint", "arm_right_5_joint", "arm_right_6_joint", "arm_right_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(TIAGO_PRO_SIZE),
    },
    Arm {
        name: "pr2_left",
        urdf: "pr2_description/urdf/pr2.urdf",
        base: Some("torso_lift_link"),
        tip: "l_gripper_tool_frame",
        lock: &[],
        joints: &["l_shoulder_pan_joint", "l_shoulder_lift_joint", "l_upper_arm_roll_joint", "l_elbow_flex_joint", "l_forearm_roll_joint", "l_wrist_flex_joint", "l_wrist_roll_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "pr2_right",
        urdf: "pr2_description/urdf/pr2.urdf",
        base: Some("torso_lift_link"),
        tip: "r_gripper_tool_frame",
        lock: &[],
        joints: &["r_shoulder_pan_joint", "r_shoulder_lift_joint", "r_upper_arm_roll_joint", "r_elbow_flex_joint", "r_forearm_roll_joint", "r_wrist_flex_joint", "r_wrist_roll_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "pr2_right_torso",
        urdf: "pr2_description/urdf/pr2.urdf",
        base: None,
        tip: "r_gripper_tool_frame",
        lock: &[],
        joints: &["torso_lift_joint", "r_shoulder_pan_joint", "r_shoulder_lift_joint", "r_upper_arm_roll_joint", "r_elbow_flex_joint", "r_forearm_roll_joint", "r_wrist_flex_joint", "r_wrist_roll_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "pr2_left_torso_locked",
        urdf: "pr2_description/urdf/pr2.urdf",
        base: None,
        tip: "l_gripper_tool_frame",
        lock: &[("torso_lift_joint", 0.1), ("l_forearm_roll_joint", 0.7)],
        joints: &["l_shoulder_pan_joint", "l_shoulder_lift_joint", "l_upper_arm_roll_joint", "l_elbow_flex_joint", "l_wrist_flex_joint", "l_wrist_roll_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "talos_full_v2_left",
        urdf: "talos_data/robots/talos_full_v2.urdf",
        base: Some("torso_2_link"),
        tip: "wrist_left_ft_tool_link",
        lock: &[],
        joints: &["arm_left_1_joint", "arm_left_2_joint", "arm_left_3_joint", "arm_left_4_joint", "arm_left_5_joint", "arm_left_6_joint", "arm_left_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "talos_full_v2_right",
        urdf: "talos_data/robots/talos_full_v2.urdf",
        base: Some("torso_2_link"),
        tip: "wrist_right_ft_tool_link",
        lock: &[],
        joints: &["arm_right_1_joint", "arm_right_2_joint", "arm_right_3_joint", "arm_right_4_joint", "arm_right_5_joint", "arm_right_6_joint", "arm_right_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "talos_full_v2_box_left",
        urdf: "talos_data/robots/talos_full_v2_box.urdf",
        base: Some("torso_2_link"),
        tip: "wrist_left_ft_tool_link",
        lock: &[],
        joints: &["arm_left_1_joint", "arm_left_2_joint", "arm_left_3_joint", "arm_left_4_joint", "arm_left_5_joint", "arm_left_6_joint", "arm_left_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "talos_full_v2_box_right",
        urdf: "talos_data/robots/talos_full_v2_box.urdf",
        base: Some("torso_2_link"),
        tip: "wrist_right_ft_tool_link",
        lock: &[],
        joints: &["arm_right_1_joint", "arm_right_2_joint", "arm_right_3_joint", "arm_right_4_joint", "arm_right_5_joint", "arm_right_6_joint", "arm_right_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "talos_reduced_left",
        urdf: "talos_data/robots/talos_reduced.urdf",
        base: Some("torso_2_link"),
        tip: "wrist_left_ft_tool_link",
        lock: &[],
        joints: &["arm_left_1_joint", "arm_left_2_joint", "arm_left_3_joint", "arm_left_4_joint", "arm_left_5_joint", "arm_left_6_joint", "arm_left_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "talos_reduced_right",
        urdf: "talos_data/robots/talos_reduced.urdf",
        base: Some("torso_2_link"),
        tip: "wrist_right_ft_tool_link",
        lock: &[],
        joints: &["arm_right_1_joint", "arm_right_2_joint", "arm_right_3_joint", "arm_right_4_joint", "arm_right_5_joint", "arm_right_6_joint", "arm_right_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "talos_reduced_box_left",
        urdf: "talos_data/robots/talos_reduced_box.urdf",
        base: Some("torso_2_link"),
        tip: "wrist_left_ft_tool_link",
        lock: &[],
        joints: &["arm_left_1_joint", "arm_left_2_joint", "arm_left_3_joint", "arm_left_4_joint", "arm_left_5_joint", "arm_left_6_joint", "arm_left_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "talos_reduced_box_right",
        urdf: "talos_data/robots/talos_reduced_box.urdf",
        base: Some("torso_2_link"),
        tip: "wrist_right_ft_tool_link",
        lock: &[],
        joints: &["arm_right_1_joint", "arm_right_2_joint", "arm_right_3_joint", "arm_right_4_joint", "arm_right_5_joint", "arm_right_6_joint", "arm_right_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "talos_reduced_corrected_left",
        urdf: "talos_data/robots/talos_reduced_corrected.urdf",
        base: Some("torso_2_link"),
        tip: "wrist_left_ft_tool_link",
        lock: &[],
        joints: &["arm_left_1_joint", "arm_left_2_joint", "arm_left_3_joint", "arm_left_4_joint", "arm_left_5_joint", "arm_left_6_joint", "arm_left_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "talos_reduced_corrected_right",
        urdf: "talos_data/robots/talos_reduced_corrected.urdf",
        base: Some("torso_2_link"),
        tip: "wrist_right_ft_tool_link",
        lock: &[],
        joints: &["arm_right_1_joint", "arm_right_2_joint", "arm_right_3_joint", "arm_right_4_joint", "arm_right_5_joint", "arm_right_6_joint", "arm_right_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "talos_left_arm",
        urdf: "talos_data/robots/talos_left_arm.urdf",
        base: None,
        tip: "wrist_left_ft_tool_link",
        lock: &[],
        joints: &["arm_left_2_joint", "arm_left_3_joint", "arm_left_4_joint", "arm_left_5_joint", "arm_left_6_joint", "arm_left_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "talos_reduced_left_torso",
        urdf: "talos_data/robots/talos_reduced.urdf",
        base: None,
        tip: "wrist_left_ft_tool_link",
        lock: &[],
        joints: &["torso_1_joint", "torso_2_joint", "arm_left_1_joint", "arm_left_2_joint", "arm_left_3_joint", "arm_left_4_joint", "arm_left_5_joint", "arm_left_6_joint", "arm_left_7_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(PAL_NC_ND),
    },
    Arm {
        name: "centauro_arm1",
        urdf: "centauro_description/urdf/centauro.urdf",
        base: Some("torso_2"),
        tip: "arm1_8",
        lock: &[],
        joints: &["j_arm1_1", "j_arm1_2", "j_arm1_3", "j_arm1_4", "j_arm1_5", "j_arm1_6"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "centauro_arm2",
        urdf: "centauro_description/urdf/centauro.urdf",
        base: Some("torso_2"),
        tip: "arm2_8",
        lock: &[],
        joints: &["j_arm2_1", "j_arm2_2", "j_arm2_3", "j_arm2_4", "j_arm2_5", "j_arm2_6"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "alex_nub_hands_left",
        urdf: "alex_description/urdf/alex_nub_hands.urdf",
        base: Some("Torso"),
        tip: "leftNub",
        lock: &[],
        joints: &["LeftShoulderPitch", "LeftShoulderRoll", "LeftShoulderYaw", "LeftElbowPitch", "LeftWristYaw", "LeftWristRoll", "LeftGripperYaw"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(ALEX_NC_ND),
    },
    Arm {
        name: "alex_nub_hands_right",
        urdf: "alex_description/urdf/alex_nub_hands.urdf",
        base: Some("Torso"),
        tip: "rightNub",
        lock: &[],
        joints: &["RightShoulderPitch", "RightShoulderRoll", "RightShoulderYaw", "RightElbowPitch", "RightWristYaw", "RightWristRoll", "RightGripperYaw"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(ALEX_NC_ND),
    },
    Arm {
        name: "alex_psyonic_hands_left",
        urdf: "alex_description/urdf/alex_psyonic_hands.urdf",
        base: Some("Torso"),
        tip: "LeftPsyonicAbilityBaseLink",
        lock: &[],
        joints: &["LeftShoulderPitch", "LeftShoulderRoll", "LeftShoulderYaw", "LeftElbowPitch", "LeftWristYaw", "LeftWristRoll", "LeftGripperYaw"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(ALEX_NC_ND),
    },
    Arm {
        name: "alex_psyonic_hands_right",
        urdf: "alex_description/urdf/alex_psyonic_hands.urdf",
        base: Some("Torso"),
        tip: "RightPsyonicAbilityBaseLink",
        lock: &[],
        joints: &["RightShoulderPitch", "RightShoulderRoll", "RightShoulderYaw", "RightElbowPitch", "RightWristYaw", "RightWristRoll", "RightGripperYaw"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(ALEX_NC_ND),
    },
    Arm {
        name: "alex_sake_hands_left",
        urdf: "alex_description/urdf/alex_sake_hands.urdf",
        base: Some("Torso"),
        tip: "LeftSakePalmLink",
        lock: &[],
        joints: &["LeftShoulderPitch", "LeftShoulderRoll", "LeftShoulderYaw", "LeftElbowPitch", "LeftWristYaw", "LeftWristRoll", "LeftGripperYaw"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(ALEX_NC_ND),
    },
    Arm {
        name: "alex_sake_hands_right",
        urdf: "alex_description/urdf/alex_sake_hands.urdf",
        base: Some("Torso"),
        tip: "RightSakePalmLink",
        lock: &[],
        joints: &["RightShoulderPitch", "RightShoulderRoll", "RightShoulderYaw", "RightElbowPitch", "RightWristYaw", "RightWristRoll", "RightGripperYaw"],
        tipless: Tipless::Tree,
        coverage: Coverage::LiveOnly(ALEX_NC_ND),
    },
    Arm {
        name: "g1_left",
        urdf: "g1_description/urdf/g1_29dof_rev_1_0.urdf",
        base: Some("torso_link"),
        tip: "left_rubber_hand",
        lock: &[],
        joints: &["left_shoulder_pitch_joint", "left_shoulder_roll_joint", "left_shoulder_yaw_joint", "left_elbow_joint", "left_wrist_roll_joint", "left_wrist_pitch_joint", "left_wrist_yaw_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "g1_right",
        urdf: "g1_description/urdf/g1_29dof_rev_1_0.urdf",
        base: Some("torso_link"),
        tip: "right_rubber_hand",
        lock: &[],
        joints: &["right_shoulder_pitch_joint", "right_shoulder_roll_joint", "right_shoulder_yaw_joint", "right_elbow_joint", "right_wrist_roll_joint", "right_wrist_pitch_joint", "right_wrist_yaw_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "g1_with_hand_left",
        urdf: "g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf",
        base: Some("torso_link"),
        tip: "left_hand_palm_link",
        lock: &[],
        joints: &["left_shoulder_pitch_joint", "left_shoulder_roll_joint", "left_shoulder_yaw_joint", "left_elbow_joint", "left_wrist_roll_joint", "left_wrist_pitch_joint", "left_wrist_yaw_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::SameChainAs("g1_left"),
    },
    Arm {
        name: "g1_with_hand_right",
        urdf: "g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf",
        base: Some("torso_link"),
        tip: "right_hand_palm_link",
        lock: &[],
        joints: &["right_shoulder_pitch_joint", "right_shoulder_roll_joint", "right_shoulder_yaw_joint", "right_elbow_joint", "right_wrist_roll_joint", "right_wrist_pitch_joint", "right_wrist_yaw_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::SameChainAs("g1_right"),
    },
    Arm {
        name: "human_left",
        urdf: "human_description/robots/human.urdf",
        base: Some("middle_thorax"),
        tip: "left_hand",
        lock: &[],
        joints: &["left_clavicle_joint_X", "left_shoulder_Z", "left_shoulder_X", "left_shoulder_Y", "left_elbow_Z", "left_elbow_Y", "left_wrist_Z", "left_wrist_X"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "human_right",
        urdf: "human_description/robots/human.urdf",
        base: Some("middle_thorax"),
        tip: "right_hand",
        lock: &[],
        joints: &["right_clavicle_joint_X", "right_shoulder_Z", "right_shoulder_X", "right_shoulder_Y", "right_elbow_Z", "right_elbow_Y", "right_wrist_Z", "right_wrist_X"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "icub_left",
        urdf: "icub_description/robots/icub.urdf",
        base: Some("chest"),
        tip: "l_hand_dh_frame",
        lock: &[],
        joints: &["l_shoulder_pitch", "l_shoulder_roll", "l_shoulder_yaw", "l_elbow", "l_wrist_prosup", "l_wrist_pitch", "l_wrist_yaw"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "icub_right",
        urdf: "icub_description/robots/icub.urdf",
        base: Some("chest"),
        tip: "r_hand_dh_frame",
        lock: &[],
        joints: &["r_shoulder_pitch", "r_shoulder_roll", "r_shoulder_yaw", "r_elbow", "r_wrist_prosup", "r_wrist_pitch", "r_wrist_yaw"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "icub_reduced_left",
        urdf: "icub_description/robots/icub_reduced.urdf",
        base: Some("chest"),
        tip: "l_hand_dh_frame",
        lock: &[],
        joints: &["l_shoulder_pitch", "l_shoulder_roll", "l_shoulder_yaw", "l_elbow", "l_wrist_prosup", "l_wrist_pitch", "l_wrist_yaw"],
        tipless: Tipless::Tree,
        coverage: Coverage::SameChainAs("icub_left"),
    },
    Arm {
        name: "icub_reduced_right",
        urdf: "icub_description/robots/icub_reduced.urdf",
        base: Some("chest"),
        tip: "r_hand_dh_frame",
        lock: &[],
        joints: &["r_shoulder_pitch", "r_shoulder_roll", "r_shoulder_yaw", "r_elbow", "r_wrist_prosup", "r_wrist_pitch", "r_wrist_yaw"],
        tipless: Tipless::Tree,
        coverage: Coverage::SameChainAs("icub_right"),
    },
    Arm {
        name: "romeo_left",
        urdf: "romeo_description/urdf/romeo.urdf",
        base: Some("torso"),
        tip: "l_gripper",
        lock: &[],
        joints: &["LShoulderPitch", "LShoulderYaw", "LElbowRoll", "LElbowYaw", "LWristRoll", "LWristYaw", "LWristPitch"],
        tipless: Tipless::Tree,
        coverage: Coverage::SameChainAs("romeo_small_left"),
    },
    Arm {
        name: "romeo_right",
        urdf: "romeo_description/urdf/romeo.urdf",
        base: Some("torso"),
        tip: "r_gripper",
        lock: &[],
        joints: &["RShoulderPitch", "RShoulderYaw", "RElbowRoll", "RElbowYaw", "RWristRoll", "RWristYaw", "RWristPitch"],
        tipless: Tipless::Tree,
        coverage: Coverage::SameChainAs("romeo_small_right"),
    },
    Arm {
        name: "romeo_small_left",
        urdf: "romeo_description/urdf/romeo_small.urdf",
        base: Some("torso"),
        tip: "l_gripper",
        lock: &[],
        joints: &["LShoulderPitch", "LShoulderYaw", "LElbowRoll", "LElbowYaw", "LWristRoll", "LWristYaw", "LWristPitch"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "romeo_small_right",
        urdf: "romeo_description/urdf/romeo_small.urdf",
        base: Some("torso"),
        tip: "r_gripper",
        lock: &[],
        joints: &["RShoulderPitch", "RShoulderYaw", "RElbowRoll", "RElbowYaw", "RWristRoll", "RWristYaw", "RWristPitch"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "romeo_laas_small_left",
        urdf: "romeo_description/urdf/romeo_laas_small.urdf",
        base: Some("torso"),
        tip: "LArm_effector",
        lock: &[],
        joints: &["LShoulderPitch_joint", "LShoulderYaw_joint", "LElbowRoll_joint", "LElbowYaw_joint", "LWristRoll_joint", "LWristYaw_joint", "LWristPitch_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "romeo_laas_small_right",
        urdf: "romeo_description/urdf/romeo_laas_small.urdf",
        base: Some("torso"),
        tip: "RArm_effector",
        lock: &[],
        joints: &["RShoulderPitch_joint", "RShoulderYaw_joint", "RElbowRoll_joint", "RElbowYaw_joint", "RWristRoll_joint", "RWristYaw_joint", "RWristPitch_joint"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "simple_humanoid_left",
        urdf: "simple_humanoid_description/urdf/simple_humanoid.urdf",
        base: Some("torso"),
        tip: "l_wrist",
        lock: &[],
        joints: &["LARM_SHOULDER_P", "LARM_SHOULDER_R", "LARM_SHOULDER_Y", "LARM_ELBOW", "LARM_WRIST_Y", "LARM_WRIST_P", "LARM_WRIST_R"],
        tipless: Tipless::Tree,
        coverage: Coverage::SameChainAs("simple_humanoid_classical_left"),
    },
    Arm {
        name: "simple_humanoid_right",
        urdf: "simple_humanoid_description/urdf/simple_humanoid.urdf",
        base: Some("torso"),
        tip: "r_wrist",
        lock: &[],
        joints: &["RARM_SHOULDER_P", "RARM_SHOULDER_R", "RARM_SHOULDER_Y", "RARM_ELBOW", "RARM_WRIST_Y", "RARM_WRIST_P", "RARM_WRIST_R"],
        tipless: Tipless::Tree,
        coverage: Coverage::SameChainAs("simple_humanoid_classical_right"),
    },
    Arm {
        name: "simple_humanoid_classical_left",
        urdf: "simple_humanoid_description/urdf/simple_humanoid_classical.urdf",
        base: Some("torso"),
        tip: "l_wrist",
        lock: &[],
        joints: &["LARM_SHOULDER_P", "LARM_SHOULDER_R", "LARM_SHOULDER_Y", "LARM_ELBOW", "LARM_WRIST_Y", "LARM_WRIST_P", "LARM_WRIST_R"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
    Arm {
        name: "simple_humanoid_classical_right",
        urdf: "simple_humanoid_description/urdf/simple_humanoid_classical.urdf",
        base: Some("torso"),
        tip: "r_wrist",
        lock: &[],
        joints: &["RARM_SHOULDER_P", "RARM_SHOULDER_R", "RARM_SHOULDER_Y", "RARM_ELBOW", "RARM_WRIST_Y", "RARM_WRIST_P", "RARM_WRIST_R"],
        tipless: Tipless::Tree,
        coverage: Coverage::Fixture,
    },
];

/// The package's URDFs without a serial arm, and why (relative to
/// `robots/`).
pub const NOT_ARMS: &[(&str, &str)] = &[
    ("a1_description/urdf/a1.urdf", "quadruped: legs of 3 joints"),
    (
        "alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf",
        "lower body only: two legs",
    ),
    (
        "allegro_hand_description/urdf/allegro_left_hand.urdf",
        "a hand: four fingers of 4 joints from the palm",
    ),
    (
        "allegro_hand_description/urdf/allegro_right_hand.urdf",
        "a hand: four fingers of 4 joints from the palm",
    ),
    (
        "anymal_b_simple_description/robots/anymal.urdf",
        "quadruped: legs of 3 joints",
    ),
    (
        "anymal_c_simple_description/urdf/anymal.urdf",
        "quadruped: legs of 3 joints",
    ),
    ("asr_twodof_description/urdf/TwoDofs.urdf", "2 joints"),
    ("b1_description/urdf/b1.urdf", "quadruped: legs of 3 joints"),
    (
        "bolt_description/robots/bolt.urdf",
        "biped: legs of 3 joints",
    ),
    (
        "borinot_description/urdf/borinot_flying_arm_2.urdf",
        "a flying arm of 2 joints",
    ),
    (
        "double_pendulum_description/urdf/double_pendulum.urdf",
        "2 joints",
    ),
    (
        "double_pendulum_description/urdf/double_pendulum_continuous.urdf",
        "2 joints",
    ),
    (
        "double_pendulum_description/urdf/double_pendulum_simple.urdf",
        "2 joints",
    ),
    (
        "finger_edu_description/robots/finger_edu.urdf",
        "one finger of 3 joints",
    ),
    (
        "go1_description/urdf/go1.urdf",
        "quadruped: legs of 3 joints",
    ),
    (
        "go2_description/urdf/go2.urdf",
        "quadruped: legs of 3 joints",
    ),
    (
        "hector_description/robots/quadrotor_base.urdf",
        "a quadrotor: no joint",
    ),
    (
        "hyq_description/robots/hyq_no_sensors.urdf",
        "quadruped: legs of 3 joints",
    ),
    (
        "iris_description/robots/iris.urdf",
        "a quadrotor: four rotor joints on the body",
    ),
    (
        "iris_description/robots/iris_simple.urdf",
        "a quadrotor: fixed joints only",
    ),
    (
        "laikago_description/urdf/laikago.urdf",
        "quadruped: legs of 3 joints",
    ),
    (
        "quadruped_description/urdf/quadruped.urdf",
        "quadruped: legs of 2 joints",
    ),
    (
        "solo_description/robots/solo.urdf",
        "quadruped: legs of 2 joints",
    ),
    (
        "solo_description/robots/solo12.urdf",
        "quadruped: legs of 3 joints",
    ),
    (
        "ur_description/urdf/ur3.urdf",
        "an empty <robot> element (a xacro stub with no link or joint); the UR3 is ur3_robot.urdf",
    ),
];
