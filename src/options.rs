//! What a front end sets: every pipeline's settings, choices and their
//! defaults, under one name.
//!
//! The command line and the Python package hand these to the pipelines of
//! [`crate::experiment`] and read back [`crate::report`]s; they call no
//! step below the pipelines. A settings type is defined beside the
//! algorithm it tunes (the Levenberg–Marquardt settings in `lsq`, the
//! relaxation's in `bound`), so that the algorithm can be read with its
//! knobs; this module is the front ends' one door to them, as a crate's
//! prelude is (`polars::prelude`, `argmin::core`). Only data lives here:
//! settings and their builders, choices (enums), defaults; never a step
//! (`tests/house.rs` checks that the front ends name no module below the
//! pipelines, and that this one re-exports no function but a default).

/// Identification: the solver, the loss, the weights, the held-out
/// validation, the simulated trials, the model's restrictions, contacts.
pub use crate::identify::contact::ContactSettings;
pub use crate::identify::restriction::Restriction;
pub use crate::identify::{HoldoutSettings, LossChoice, LossKind, MonteCarloSettings, Weights};
pub use crate::lsq::levmar::LmSettings;

/// The gross-error test: its choice and its default significance level.
pub use crate::lsq::outliers::{ALPHA as DEFAULT_OUTLIER_ALPHA, OutlierChoice};

/// Selection: the algorithm, the criterion, its settings, continuous
/// refinement, the information of poses already measured, and the
/// default rounds of iterated local search.
pub use crate::criterion::Prior;
pub use crate::select::{
    Algorithm, CriterionKind, RefineSettings, Settings as SelectSettings, default_ils_rounds,
};

/// The relaxation bound: its solver and settings, and the weight above
/// which a pose counts as in the relaxation's support.
pub use crate::bound::gap::WEIGHT_TOL as SUPPORT_WEIGHT;
pub use crate::bound::{BoundSettings, RelaxationSolver};

/// Pools: where poses come from, the filters, the joint-limit margin.
pub use crate::collision::Obstacle;
pub use crate::pool::{
    DEFAULT_COUNT, DEFAULT_LEVELS, DEFAULT_URDF_MARGIN_DEG, PoolFilter, PoolKind, PoolSource,
    PoolSpec, default_margin_deg,
};

/// Sensors' set-up: a camera's mounting, intrinsics and view, where a
/// target is seen from.
pub use crate::measure::Visibility;
pub use crate::measure::camera::Mounting;
pub use crate::measure::pinhole::Intrinsics;
pub use crate::pool::camera_view::{CameraView, DEFAULT_MAX_VIEW_ANGLE_DEG};

/// A placement from `X,Y,Z,ROLL,PITCH,YAW` (metres, radians; rpy as in a
/// URDF's `origin`): how a front end reads a camera's or target's
/// placement given as six numbers.
pub use crate::pool::camera_view::placement;
