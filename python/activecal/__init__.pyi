"""activecal from Python: choose the poses to measure for kinematic robot
calibration (D-optimal design), then calibrate from the measurements.

Units: lengths in metres and angles in radians (joint values, limits,
marker offsets, estimates and their σ); the errors reported in
`Calibration.residuals` and `Design.predicted` are in millimetres and
degrees, as their keys say (`position_rms_mm`, `orientation_rms_deg`).
Arrays are float64 NumPy arrays; anything NumPy reads as one is accepted,
checked for shape and finiteness. Wrong input raises `Error` whose message
starts with the argument's name.
"""

from os import PathLike
from typing import Any, Callable, Mapping, Optional, Sequence, Tuple, Union, final

import numpy as np
import numpy.typing as npt

__version__: str

__all__ = [
    "Calibration",
    "CameraCalibration",
    "CameraDesign",
    "ContactCalibration",
    "Design",
    "ComputationError",
    "Error",
    "FileError",
    "InputError",
    "InternalError",
    "Page",
    "Pool",
    "ResourceError",
    "Robot",
    "__version__",
    "bound",
    "calibrate",
    "calibrate_camera",
    "calibrate_contacts",
    "detect",
    "evaluate",
    "extract",
    "gap",
    "pool",
    "select",
    "select_camera",
]

_Path = Union[str, "PathLike[str]"]
_Marker = Union[str, Tuple[str, Sequence[float]]]

class Error(Exception):
    """Bad input or a failed computation, with the library's message: the
    argument's name first when one argument is wrong (``q: expected shape
    (6,) ...``). Every error activecal raises is one of its subclasses."""

class InputError(Error, ValueError):
    """A wrong argument (its name first) or a wrong value in an input file
    (the file and the place named)."""

class FileError(Error, OSError):
    """A file that could not be read or written, or an output that exists
    when a writer is given overwrite=False."""

class ResourceError(Error, RuntimeError):
    """Work too large for the memory or size limits, with the figure."""

class ComputationError(Error, RuntimeError):
    """A computation that cannot be done on these (valid) inputs."""

class InternalError(Error, RuntimeError):
    """A defect in activecal: please report it with the message."""

@final
class Robot:
    """A robot model: a serial chain, its joint limits, the unknowns a
    calibration estimates and the sensor it is measured with. Immutable."""

    @staticmethod
    def from_urdf(
        path: _Path,
        tip: Optional[str] = None,
        base: Optional[str] = None,
        marker: Optional[Union[_Marker, Sequence[_Marker]]] = None,
        lock: Optional[Mapping[str, float]] = None,
        frames: Optional[_Path] = None,
        pose: bool = False,
        kinematics: Optional[_Path] = None,
    ) -> "Robot":
        """Imports the chain base..tip of a URDF file.

        tip, base: link names (base defaults to the URDF's root; the tip is
        required on a tree). marker: a marker measured on the tip,
        ``"LINK@X,Y,Z"`` or ``(link, (x, y, z))``, the offset in metres in
        the link's frame, or a list of them; each offset is estimated by
        `calibrate`. lock: joints held fixed, {joint: value} in radians or
        metres. frames: a frames file (as `Calibration.write_frames`
        writes) mounting the chain in its measurement frame with its tool.
        pose: full-pose measurements (position and orientation).
        kinematics: a kinematics file whose joint origins replace the
        URDF's: Universal Robots' ``default_kinematics.yaml`` (a factory
        file, or `Calibration.write_ur_kinematics`'s) or a per-joint
        origins file (`Calibration.write_joint_origins`).
        """
    @staticmethod
    def builtin(name: str) -> "Robot":
        """A built-in robot: ``"puma560"``, ``"ur5"`` or ``"stanford"``;
        ``"NAME:pose"`` for full-pose measurements."""
    @property
    def name(self) -> str:
        """The robot's name as design files record it (a built-in name or
        the URDF's path with its chain)."""
    @property
    def dof(self) -> int:
        """Number of joints."""
    @property
    def joint_names(self) -> list[str]:
        """The joints' names in configuration order (a URDF's joint names)."""
    @property
    def limits(self) -> npt.NDArray[np.float64]:
        """Joint limits, shape (dof, 2), [lower, upper]: radians for a
        revolute joint, metres for a prismatic one."""
    @property
    def unknowns(self) -> list[str]:
        """Names of the parameters a calibration estimates, in order: the
        robot's unknowns, then each marker's offset (``marker1_x`` ...)."""
    @property
    def measures_orientation(self) -> bool:
        """Whether orientations are measured too (a full-pose sensor)."""
    def fk(
        self, q: npt.ArrayLike
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """Forward kinematics of the nominal model at joint values q (shape
        (dof,), radians or metres, each within its joint's limits): (R, p),
        the end frame's orientation (3×3 rotation matrix in the base frame)
        and position (shape (3,), metres)."""

    def jacobian(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The identification Jacobian of the nominal model at joint values
        q (shape (dof,), radians or metres): shape (rows, len(unknowns)),
        each measured coordinate's change (metres) per unit of each
        parameter (metres or radians), columns in the order of `unknowns`;
        3 rows for a point, 6 for a full pose (orientation rows weighed by
        the robot's orientation scale, metres per radian), 3 per marker."""

@final
class Page:
    """A report's 3D page (``index.html`` of its report folder): one
    self-contained HTML page, shown inline by Jupyter (``_repr_html_``:
    the page in an iframe's ``srcdoc``)."""

    @property
    def html(self) -> str:
        """The page's HTML text, byte for byte ``index.html`` of the
        command line's report folder."""
    def _repr_html_(self) -> str: ...
    def write(self, path: _Path, overwrite: bool = True) -> None:
        """Writes the page alone to `path` (an existing file is replaced;
        overwrite=False refuses it with `FileError`)."""

@final
class Design:
    """The poses `select` chose, in visiting order (see `select`'s order)."""

    @property
    def q(self) -> npt.NDArray[np.float64]:
        """Joint values of the poses in visiting order, shape (n, dof),
        radians or metres, as visited (a joint may stand a whole turn from
        the pool's value)."""
    @property
    def ids(self) -> list[int]:
        """Each pose's id in its pool (a sample's number, a lattice index),
        in visiting order (the rows of `q`)."""
    @property
    def joint_names(self) -> list[str]:
        """The columns of `q`."""
    @property
    def ln_oid(self) -> float:
        """ln OI_D = ln det(XᵀX), X the design's identification Jacobian
        (metres per parameter unit) at the nominal parameters."""
    @property
    def predicted(self) -> Optional[dict[str, Any]]:
        """With `noise`: the error predicted after calibrating with these
        poses, at 1000 random configurations (keys ``noise_m``,
        ``configurations``, ``position_rms_mm``, ``position_p95_mm`` and
        for full poses ``orientation_rms_deg``); else None (also for a
        design that cannot identify the robot)."""
    @property
    def report(self) -> dict[str, Any]:
        """The dict ``activecal select --json`` prints for the same inputs
        and order (``tour``: the visiting order's figures; ``moves``: the
        moves' collision check, with collision filters)."""
    def write(self, path: _Path, overwrite: bool = True) -> None:
        """Writes the design by the extension of path, as ``activecal
        select --out`` does: .json (the design file), .csv (joint values,
        one pose a row, a header of joint names) or .yaml (named joint
        configurations). An existing file is replaced, as pandas and NumPy
        do; overwrite=False refuses it (``FileError``)."""
    def bound(
        self, progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None
    ) -> dict[str, Any]:
        """The certified bound on ln det of every design of this size from
        the same pool (the continuous relaxation, with the existing poses'
        information when given) and this design's D-efficiency against it:
        the dict ``activecal gap --json`` prints (``ln_oid``, ``ln_bound``,
        ``d_efficiency`` in (0, 1], ``bound_status``, ``certificate_gap``).
        Computed on each call; the GIL is released."""
    def how_many(
        self,
        noise: Optional[float] = None,
        target_error: Optional[float] = None,
        progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None,
    ) -> dict[str, Any]:
        """How many poses to measure: for each design size from the fewest
        that identify the unknowns (``n_min``) to three times that, and this
        design's, the best design this selection's settings find, its
        D-efficiency against the certified bound and the position error
        predicted after calibrating with it at 1000 random configurations
        (mm); the dict ``activecal select --report DIR`` writes as
        ``how_many_poses`` (``points``, ``skipped``, ``recommended``: the
        size and its rule, ``target`` or ``knee``). noise: the sensor's σ
        per coordinate, metres (default: select's noise, else 0.01 as the
        command line). target_error: the position RMS to reach, mm.
        A selection and a bound per size: seconds to minutes; the GIL is
        released."""
    def write_report(
        self,
        path: _Path,
        overwrite: bool = True,
        noise: Optional[float] = None,
        target_error: Optional[float] = None,
        progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None,
    ) -> None:
        """Writes the report folder ``activecal select --report DIR``
        writes: report.md, report.json, the figures (PNG and SVG) and
        ``index.html``, the 3D page of the poses in visiting order. Computes
        the "how many poses" curve (`how_many`'s noise, target_error and
        progress; seconds to minutes). An existing directory is replaced
        whole (never one holding the robot's files); overwrite=False
        refuses a non-empty one with `FileError`."""
    def show(
        self,
        noise: Optional[float] = None,
        progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None,
    ) -> Page:
        """The 3D page of `write_report`'s folder, shown inline by
        Jupyter (noise and progress as `write_report` takes them; the page
        does not show the curve's recommendation)."""
    def __len__(self) -> int: ...

@final
class Pool:
    """Candidate poses and their identification Jacobian: what `select`
    chooses from."""

    @property
    def q(self) -> npt.NDArray[np.float64]:
        """Joint values of the candidates, shape (n, dof), radians or metres."""
    @property
    def ids(self) -> list[int]:
        """Each candidate's id (a sample's number, a lattice index, a row of
        the array given)."""
    @property
    def joint_names(self) -> list[str]:
        """The columns of `q`."""
    @property
    def stats(self) -> dict[str, Any]:
        """What the filters kept and removed (``candidates``, ``kept``,
        ``filters``: each one's ``removed`` of ``seen``), as the command
        line's ``pool_stats``."""
    def __len__(self) -> int: ...

def pool(
    robot: Robot,
    source: Union[str, npt.ArrayLike, None] = None,
    count: Optional[int] = None,
    levels: Optional[int] = None,
    pool_seed: Optional[int] = None,
    margin: Optional[float] = None,
    self_collision: bool = False,
    srdf: Optional[_Path] = None,
    package_dirs: Optional[list[_Path]] = None,
    floor: Optional[float] = None,
    obstacles: Optional[list[str]] = None,
    clearance: float = 0.0,
    progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None,
) -> Pool:
    """Candidate poses for `select`. source: ``"random"`` (default) or
    ``"sobol"`` (count samples inside the joint limits less margin degrees,
    default 4096; pool_seed), ``"lattice"`` (levels values per joint,
    default 5) or an (n, dof) array of your own joint values (radians or
    metres). Poses the sensor does not see are dropped; with
    self_collision (pairs listed by srdf skipped), floor (a height in the
    base frame, metres) or obstacles (``"box:x,y,z,sx,sy,sz"`` ..., base
    frame, metres, as ``--obstacle``), the poses where the robot touches
    itself or them within clearance metres (meshes found in package_dirs).
    The GIL is released while it runs."""

def select(
    robot: Robot,
    n: int,
    pool: Union[str, Pool, npt.ArrayLike, None] = None,
    count: Optional[int] = None,
    levels: Optional[int] = None,
    pool_seed: Optional[int] = None,
    margin: Optional[float] = None,
    algorithm: str = "eae",
    seed: int = 1,
    starts: int = 2,
    ils: Optional[int] = None,
    kick: int = 3,
    noise: Optional[float] = None,
    existing: Optional[npt.ArrayLike] = None,
    order: Optional[str] = None,
    progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None,
) -> Design:
    """Chooses n poses to measure from a pool of candidates by D-optimal
    design (maximising ln det XᵀX), as ``activecal select`` does with the
    same options. The GIL is released while it runs.

    pool: a `Pool` (from `pool`, with its filters), an (n, dof) array of
    your own candidate joint values, or ``"random"`` (default) or ``"sobol"`` (count samples inside the joint
    limits, default 4096; pool_seed: the random stream's seed, default 0,
    or the Sobol scramble's, default none) or ``"lattice"`` (levels values
    per joint, default 5). margin: degrees kept inside every revolute
    joint's limits (default 2 for a URDF robot's generated pool, else 0).
    algorithm: ``"eae"``, ``"fedorov"``, ``"detmax"``, ``"random"`` ... as
    the command line names them. seed: every random choice of the search
    (default 1, the command line's). starts: independent starts, the best
    kept. ils: rounds of iterated local search (default: by pool size, as
    the command line). kick: poses exchanged per round. noise: the
    sensor's σ per coordinate, metres; the design then predicts the error
    after calibration (`Design.predicted`). existing: an (m, dof) array
    of poses already measured: the new poses add most to their
    information (as ``--existing``). Arrays of joint values may be pandas
    DataFrames with a column per joint (by name, in any order). order:
    ``"time"`` (the poses in the order quickest to visit at the joint speed
    limits of the robot's description, 1 rad/s where it states none) or
    ``"none"`` (selection order); default ``"time"`` when the description
    states joint speeds, else ``"none"``, as ``--order``. Either way, with
    collision filters on the pool the moves are checked and a pose the path
    cannot reach freely is turned, routed round or exchanged
    (``report["moves"]``, ``report["swapped"]``). progress: a callable
    ``progress(task, done, total, note)`` called as the work advances (at
    most every 0.1 s per task; total None when unknown; note ``"done"`` at a
    task's end); an exception it raises is raised when the work ends. The
    same argument on `pool`, `calibrate` and `Design.bound`.
    """

def bound(
    robot: Robot,
    n: int,
    pool: Union["Pool", npt.ArrayLike, str, None] = None,
    count: Optional[int] = None,
    levels: Optional[int] = None,
    pool_seed: Optional[int] = None,
    margin: Optional[float] = None,
    existing: Optional[npt.ArrayLike] = None,
    weights: bool = False,
    progress: Optional[Callable[[str, int, Optional[int], str], None]] = None,
) -> dict[str, Any]:
    """The certified upper bound on ln det(XᵀX) of every design of `n`
    poses from the pool (the D criterion's continuous relaxation, solved to
    a certified duality gap): the dict `activecal bound --json` prints
    (`ln_bound`, `status`, the pool, the settings; `support`, the
    relaxation's weight per pose, when `weights`). Pool arguments as
    `select`; `existing`: joint values (radians) of poses already measured."""
    ...

def gap(
    design: Design,
    progress: Optional[Callable[[str, int, Optional[int], str], None]] = None,
) -> dict[str, Any]:
    """`design.bound()`: the design's D-efficiency against the certified
    bound over its own pool, the dict `activecal gap --json` prints."""
    ...

@final
class Calibration:
    """The result of `calibrate`."""

    @property
    def converged(self) -> bool:
        """Whether the fit converged (only then is the robot written)."""
    @property
    def estimate(self) -> dict[str, float]:
        """{parameter name: estimated value}, metres and radians."""
    @property
    def sigma(self) -> Optional[dict[str, float]]:
        """{parameter name: standard deviation}, metres and radians; None
        when the fit is rank deficient."""
    @property
    def residuals(self) -> dict[str, Any]:
        """Errors of the fitted model on the data: ``position_rms_mm``,
        ``position_max_mm``, ``orientation_rms_deg`` (full poses) and per
        pose."""
    @property
    def holdout(self) -> Optional[dict[str, Any]]:
        """With `holdout`: each split's errors of the fitted and the nominal
        model on the poses it did not see, and their means (mm, degrees)."""
    @property
    def noise(self) -> Optional[dict[str, Any]]:
        """The residual blocks' σ's the fit weighed by (mm, degrees) with
        their degrees of freedom."""
    @property
    def frames(self) -> Optional[dict[str, Any]]:
        """The calibrated robot in its URDF's terms (measurement frame,
        tool or markers, each joint origin's change with σ; a coordinate no
        estimated unknown moves has σ None and is listed under ``fixed``):
        the frames file's content. None for a built-in robot."""
    @property
    def report(self) -> dict[str, Any]:
        """The dict ``activecal calibrate --measurements FILE --json``
        prints for a file holding the same values (``measurements`` names
        the arrays here, not a file)."""
    def write_urdf(self, path: _Path, overwrite: bool = True) -> None:
        """Writes the calibrated URDF: the robot's own file with only the
        chain's joint origins changed (a built-in robot: its chain as a
        URDF). Refused (Error) when the fit did not converge."""
    def write_frames(self, path: _Path, overwrite: bool = True) -> None:
        """Writes the frames file (YAML): the measurement frame, the tool
        or markers and the joint-origin changes with their σ, as
        ``activecal calibrate --out cal.yaml`` does. URDF robots only;
        refused when the fit did not converge."""
    def write_ur_kinematics(self, path: _Path, overwrite: bool = True) -> None:
        """Writes the calibrated joint origins as Universal Robots'
        ``default_kinematics.yaml`` (per joint ``x y z`` in metres, ``roll
        pitch yaw`` in radians, and a ``hash``), which ``ur_description``'s
        xacro reads; as ``activecal calibrate --out default_kinematics.yaml``.
        URDF robots with the six UR joints only; refused when the fit did
        not converge."""
    def write_joint_origins(self, path: _Path, overwrite: bool = True) -> None:
        """Writes the calibrated joint origins as the per-joint origins
        file (``JOINT: {xyz: [m], rpy: [rad]}``), which a xacro description
        reads with ``xacro.load_yaml``; as ``activecal calibrate --out
        cal_origins.yaml``. URDF robots only; refused when the fit did not
        converge."""
    def write_joint_offsets(
        self, path: _Path, unit: str = "rad", sign: str = "add", overwrite: bool = True
    ) -> None:
        """Writes the joints' zero offsets as a driver takes them: unit
        ``"rad"`` or ``"deg"`` (prismatic joints in metres), sign ``"add"``
        (``q = q_encoder + offset``) or ``"subtract"`` (``q = q_encoder -
        offset``); as ``activecal calibrate --out x_joint_offsets.yaml
        --offset-unit --offset-sign``. URDF robots only; refused when the
        fit did not converge."""
    def write_report(self, path: _Path, overwrite: bool = True) -> None:
        """Writes the report folder ``activecal calibrate --measurements
        FILE --report DIR`` writes: report.md, report.json, the figures and
        ``index.html``, the 3D page of the measured poses (nominal and
        calibrated robot overlaid, measured and fitted points, residuals
        magnified, flagged poses marked). An existing directory is replaced
        whole (never one holding the robot's files); overwrite=False
        refuses a non-empty one with `FileError`."""
    def show(self) -> Page:
        """The 3D page of `write_report`'s folder, shown inline by
        Jupyter."""

def calibrate(
    robot: Robot,
    q: Optional[npt.ArrayLike] = None,
    points: Union[npt.ArrayLike, str, None] = None,
    orientations: Optional[npt.ArrayLike] = None,
    fix: Optional[Sequence[str]] = None,
    free: Optional[Sequence[str]] = None,
    max_iterations: int = 200,
    loss: str = "l2",
    loss_scale: Optional[float] = None,
    weights: Optional[str] = None,
    orientation_scale: Optional[float] = None,
    holdout: Optional[float] = None,
    splits: int = 4,
    seed: int = 0,
    compliance: bool = False,
    outliers: str = "drop",
    outlier_rate: float = 0.01,
    noise: Optional[float] = None,
    orientation_noise: Optional[float] = None,
    progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None,
    unknowns: str = "all",
    keep_axis_relations: bool = False,
    bag: Optional[_Path] = None,
    joints: str = "/joint_states",
    poses: Optional[str] = None,
    tf: Optional[str] = None,
    time_offset: Optional[float] = None,
    max_offset: float = 10.0,
    rest_speed: float = 0.005,
    rest_min: float = 0.5,
    settle: float = 0.2,
    design: Optional[_Path] = None,
    design_tolerance: float = 0.01,
) -> Calibration:
    """Calibrates the robot from measured poses, as ``activecal calibrate
    --measurements FILE`` does from a file holding the same values, or
    from a ROS 2 bag (``bag=``) as ``activecal calibrate --bag BAG`` does.
    The GIL is released while it runs.

    bag: a rosbag2 folder, or one ``.mcap`` or ``.db3`` file, instead of q
    and points: one pose per rest of the joints, read as `extract` reads
    it, with ``points`` the bag's ``PointStamped`` topic (a str), or
    ``poses`` (``PoseStamped``/``TransformStamped``) or ``tf``
    (``"PARENT:CHILD"``); joints, time_offset, max_offset, rest_speed,
    rest_min, settle, design (the design file the run followed) and
    design_tolerance as `extract` takes them. The clock offset, when
    estimated, is estimated again with the calibrated model (and the bag
    fitted once more when it moved), as the command line does; the
    extraction and both estimates are in ``report["bag"]``.

    q: shape (n, dof), joint values in radians or metres. points: shape
    (n, 3), the measured positions in the sensor's frame, metres (shape
    (n, K, 3) for a robot with K markers). orientations: shape (n, 3, 3),
    measured rotation matrices, for a full-pose robot only. fix: unknowns
    held at their nominal values; free: parameters estimated besides the
    unknowns (names as in `Calibration.estimate`). max_iterations:
    Levenberg–Marquardt's limit. loss: ``"l2"``, or ``"huber"`` /
    ``"cauchy"`` with loss_scale (metres: a pose's residual norm where the
    loss turns robust). weights: ``"estimated"`` (default: each residual
    block's σ from its own residuals) or ``"fixed"`` (a radian of
    orientation weighs orientation_scale metres; giving orientation_scale
    implies ``"fixed"``). holdout: the fraction of poses held out in each
    of `splits` random splits seeded by `seed` (`Calibration.holdout`).
    compliance: also estimate a torsional compliance per joint (rad/(N·m))
    deflected by the gravity torques of the URDF's <inertial> elements
    (``report["compliance"]``), as ``--compliance``. q and points may be
    pandas DataFrames: q with a column per joint (by name, in any order,
    others ignored), points with columns ``x, y, z`` (``x1, y1, z1`` ...
    for K markers). unknowns: ``"all"`` (the chain's complete set) or
    ``"offsets"`` (only the joints' zero offsets, the measurement frame and
    the tool; link lengths and twists held), as ``--unknowns``.
    keep_axis_relations: hold the unknowns that would change the nominal
    model's parallel, perpendicular or intersecting joint axes, so
    closed-form inverse kinematics still apply, as
    ``--keep-axis-relations``. With either restriction the same data are
    also fitted with every unknown: ``report["full_model_gain"]`` gives
    both models' predicted (and held-out) errors, what the full model
    gains and the relations held.
    """

def evaluate(
    model: Union[Robot, Calibration],
    q: npt.ArrayLike,
    points: npt.ArrayLike,
    orientations: Optional[npt.ArrayLike] = None,
) -> dict[str, Any]:
    """The errors of a model on measured poses (``position_rms_mm``,
    ``position_max_mm``, ``orientation_rms_deg`` for full poses, and per
    pose), as ``activecal evaluate --json`` prints them under
    ``residuals``. model: a `Robot` (e.g. the calibrated URDF and frames
    file loaded back) or a `Calibration` (its fitted model). q, points and
    orientations as `calibrate` takes them: poses the fit did not see
    judge it."""

@final
class ContactCalibration:
    """The result of `calibrate_contacts`."""

    @property
    def converged(self) -> bool: ...
    @property
    def estimate(self) -> dict[str, float]:
        """{parameter: value}, metres and radians: the robot's unknowns, the
        tool offset and each point's coordinates."""
    @property
    def sigma(self) -> Optional[dict[str, float]]:
        """{parameter: σ}; None without a full-rank Jacobian."""
    @property
    def points(self) -> dict[str, Tuple[float, float, float]]:
        """The fitted points in the base frame, metres."""
    @property
    def tool_offset(self) -> Tuple[float, float, float]:
        """The tool point (ball centre) on the tip link, metres."""
    @property
    def predicted_true_error(self) -> Optional[dict[str, Any]]:
        """The tool point's predicted true error at 1000 random
        configurations (``rms_mm``, ``configurations``): what held-out
        placements cannot see."""
    @property
    def report(self) -> dict[str, Any]:
        """The dict ``activecal calibrate --measurements FILE --json``
        prints for a contact file with the same rows."""
    def write_urdf(self, path: _Path, overwrite: bool = True) -> None:
        """The calibrated URDF (refused unless converged and plausible)."""
    def write_frames(self, path: _Path, overwrite: bool = True) -> None:
        """The frames file: the ball centre as ``point``, the fitted points
        under ``contacts``."""
    def write_report(self, path: _Path, overwrite: bool = True) -> None:
        """Writes the report folder ``activecal calibrate --measurements
        FILE --report DIR`` writes for a contact file with the same rows:
        report.md, report.json, the figures and ``index.html``, the 3D page
        of the robot at each contact with the fitted sockets (spheres) and
        planes (translucent squares). An existing directory is replaced
        whole (never one holding the robot's files); overwrite=False
        refuses a non-empty one with `FileError`."""
    def show(self) -> Page:
        """The 3D page of `write_report`'s folder, shown inline by
        Jupyter."""

def calibrate_contacts(
    robot: Robot,
    q: npt.ArrayLike,
    points: Sequence[str],
    distances: Union[Mapping[Tuple[str, str], float], Sequence[Tuple[str, str, float]]],
    free: Optional[Sequence[str]] = None,
    max_iterations: int = 200,
    loss: str = "l2",
    loss_scale: Optional[float] = None,
    outliers: str = "drop",
    outlier_rate: float = 0.01,
    progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None,
) -> ContactCalibration:
    """Calibrates the robot from contacts, as ``activecal calibrate
    --measurements FILE --point-distance A,B=M`` does with a contact file of
    the same rows. q: (n, dof) joint values at which the tool point (the
    chain's tip, a ball centre) touched a fixed point; points: the name of
    the point each row touched; distances: lengths known between points,
    metres (at least one: contacts alone leave the scale free). free:
    parameters never fixed; loss, loss_scale, max_iterations and progress
    as `calibrate` takes them."""

@final
class CameraCalibration:
    """The result of `calibrate_camera`."""

    @property
    def converged(self) -> bool:
        """Whether the fit converged (only then are files written)."""
    @property
    def refused(self) -> Optional[str]:
        """Why the calibration may not be written (None when it may): the
        reason the command line refuses it with (exit status 3)."""
    @property
    def estimate(self) -> dict[str, float]:
        """{unknown: value}: the robot's unknowns (metres, radians),
        ``camera_x … target_rz`` (the fit's placements) and, refined, the
        intrinsics ``fx fy cx cy`` (px) and ``k1 k2 p1 p2 k3``."""
    @property
    def sigma(self) -> Optional[dict[str, float]]:
        """{unknown: σ}; None without a covariance."""
    @property
    def sigma_px(self) -> Optional[float]:
        """The pixel noise σ estimated from the residuals (one variance
        component), px."""
    @property
    def rms_px(self) -> float:
        """The RMS pixel error calibrated, px."""
    @property
    def camera(self) -> Optional[npt.NDArray[np.float64]]:
        """The camera's optical frame (x right, y down, z forward) in its
        link (``report["camera"]["camera"]["parent"]``: the base link
        eye-to-hand, the tip link eye-in-hand, the camera's link), a 4×4
        homogeneous matrix, metres; None for a robot not from a URDF."""
    @property
    def target(self) -> Optional[npt.NDArray[np.float64]]:
        """The target's frame in its link (``report["camera"]["target"]
        ["parent"]``), a 4×4 homogeneous matrix, metres; None as for
        ``camera``."""
    @property
    def report(self) -> dict[str, Any]:
        """The dict ``activecal calibrate --observations FILE --json``
        prints (``out`` empty)."""
    def write_urdf(self, path: _Path, overwrite: bool = True) -> None:
        """Your URDF with the calibrated joint origins (refused unless
        converged)."""
    def write_frames(self, path: _Path, overwrite: bool = True) -> None:
        """The frames file with the ``camera`` block (both placements with
        σ, the pixel σ and RMS)."""
    def write_camera_info(self, path: _Path, overwrite: bool = True) -> None:
        """The refined intrinsics as a ROS camera_info ``.yaml``, the camera
        named by the file's stem (only with ``refine_intrinsics=True`` and
        a converged fit), as ``--out-camera-info`` writes it."""

def detect(
    images: _Path,
    target: Union[_Path, Mapping[str, Any]],
    camera_info: Union[_Path, Mapping[str, Any]],
    *,
    robot: Robot,
    joints: _Path,
) -> Any:
    """Detects the target's points in a camera's images, as ``activecal
    calibrate --images IMAGES --joints JOINTS --save-observations F``
    does. images: a folder of PNG or JPEG images, a glob pattern or one file.
    target: a target YAML path or a dict (a ``checkerboard`` or a
    ``charuco`` board with its ``dictionary``). camera_info: a ROS
    camera_info or OpenCV YAML path, or a dict. robot: the robot whose
    joint values ``joints`` holds; joints: a CSV with an ``image`` column
    (each image's file name) and a column per joint. Returns a pandas
    DataFrame with the observations CSV's columns ``pose, <joint names>,
    feature, u, v`` (pixels), which `calibrate_camera` takes;
    ``df.attrs["images"]`` lists every image with what became of it
    (``status`` ``"found"`` with its figures, or ``"left_out"`` with its
    ``reason``)."""

def calibrate_camera(
    robot: Robot,
    observations: Optional[Union[_Path, Any]] = None,
    camera_info: Optional[Union[_Path, Mapping[str, Any]]] = None,
    target: Optional[Union[_Path, Mapping[str, Any]]] = None,
    *,
    images: Optional[Union[_Path, Sequence[_Path]]] = None,
    joints: Optional[Union[_Path, Any]] = None,
    camera_pose: Optional[Sequence[float]] = None,
    target_pose: Optional[Sequence[float]] = None,
    mounting: Optional[str] = None,
    camera_link: Optional[str] = None,
    refine_intrinsics: bool = False,
    outliers: str = "drop",
    outlier_rate: float = 0.01,
    pixel_noise: Optional[float] = None,
    progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None,
) -> CameraCalibration:
    """Calibrates the robot from a camera's pixels of a target, as
    ``activecal calibrate --observations FILE --json`` does with the same
    files. observations: a CSV path or a pandas DataFrame with its columns
    ``pose, <joint names>, feature, u, v`` (one row a point seen, pixels;
    a DataFrame's errors name the line of its CSV, line 2 its first row).
    Or, instead, images: a folder of PNG or JPEG images, a glob pattern, one file
    or a list of files (each a pose), with joints: a CSV path or a pandas
    DataFrame with an ``image`` column (each image's file name) and a
    column per joint, as ``activecal calibrate --images DIR --joints FILE``
    takes them: the target's points are detected by the library (as
    `detect` does) and ``report["images"]`` lists what became of each
    image.
    camera_info: a ROS camera_info or OpenCV YAML path, or a dict of a ROS
    camera_info's keys. target: a target YAML path, or a dict
    (``{"checkerboard": {"rows": 6, "cols": 8, "square": 0.025}}`` or
    ``{"points": [{"id": 0, "xyz": [x, y, z]}, ...]}``). mounting:
    ``"eye-to-hand"`` (the camera fixed, the target on the tip link) or
    ``"eye-in-hand"``; or camera_link: the robot's link a camera is on (a
    head; the chain from it to the tip is fitted). camera_pose,
    target_pose: rough placements X, Y, Z, ROLL, PITCH, YAW (metres,
    radians, rpy as in URDF), the fit's start; one left out is computed
    from the pixels (PnP and the closed-form hand-eye; the report's
    ``start`` says which). refine_intrinsics: fit the
    intrinsics too. Bad input raises `InputError` naming the argument (and
    the file, line and column)."""

@final
class CameraDesign:
    """The result of `select_camera`."""

    @property
    def q(self) -> npt.NDArray[np.float64]:
        """(n, dof) chosen configurations, radians or metres, in the order
        chosen."""
    @property
    def candidates(self) -> list[int]:
        """Each one's index in the samples."""
    @property
    def points_seen(self) -> list[int]:
        """The target points each will see."""
    @property
    def joint_names(self) -> list[str]:
        """The columns of ``q``."""
    @property
    def poses(self) -> Any:
        """A pandas DataFrame with the columns of ``select --out
        design.csv``: candidate, the joints, points_seen."""
    def how_many(
        self,
        pixel_noise: Optional[float] = None,
        target_error: Optional[float] = None,
        progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None,
    ) -> dict[str, Any]:
        """How many poses: the curve on the design's visible pool: the dict
        ``activecal select --camera-info ... --report DIR`` writes as
        ``how_many_poses`` in report.json (``n_min`` = ⌈p / 6⌉, ``points``
        with ``n``, ``d_efficiency``, the ``predicted`` true errors in mm,
        ``noise_px``, ``recommended``) for the pixel noise σ ``pixel_noise``
        (px; the design's ``pixel_noise``, else 0.3) and, with
        ``target_error`` (mm), the fewest poses predicted to reach it."""
    def write_report(
        self,
        path: _Path,
        overwrite: bool = True,
        pixel_noise: Optional[float] = None,
        target_error: Optional[float] = None,
        progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None,
    ) -> None:
        """Writes the report folder ``activecal select --camera-info ...
        --report DIR`` writes: report.md, report.json, the figures (PNG and
        SVG) and ``index.html``, the 3D page of the poses with the camera's
        field of view, the board and the lines of sight checked. Computes
        the "how many poses" curve (`how_many`'s pixel_noise, target_error
        and progress; seconds to minutes). An existing directory is
        replaced whole (never one holding the robot's files);
        overwrite=False refuses a non-empty one with `FileError`."""
    def show(
        self,
        pixel_noise: Optional[float] = None,
        progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None,
    ) -> Page:
        """The 3D page of `write_report`'s folder, shown inline by
        Jupyter (pixel_noise and progress as `write_report` takes them)."""
    @property
    def report(self) -> dict[str, Any]:
        """The dict ``activecal select --camera-info ... --json`` prints
        (``out`` empty)."""

def select_camera(
    robot: Robot,
    camera_info: Union[_Path, Mapping[str, Any]],
    target: Union[_Path, Mapping[str, Any]],
    *,
    n: int,
    camera_pose: Sequence[float],
    target_pose: Sequence[float],
    mounting: Optional[str] = None,
    camera_link: Optional[str] = None,
    count: int = 20000,
    pool_seed: int = 0,
    seed: int = 1,
    min_visible: float = 1.0,
    image_margin: float = 10.0,
    max_view_angle: float = 60.0,
    distance: Tuple[float, float] = ...,
    gap: bool = False,
    pixel_noise: Optional[float] = None,
    line_of_sight: bool = False,
    self_collision: bool = False,
    srdf: Optional[_Path] = None,
    package_dirs: Optional[Sequence[_Path]] = None,
    floor: Optional[float] = None,
    obstacles: Optional[Sequence[str]] = None,
    progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None,
) -> CameraDesign:
    """Chooses n poses for a camera, as ``activecal select --camera-info
    ... --json`` does with the same files and options. camera_info, target, mounting,
    camera_link, camera_pose and target_pose as `calibrate_camera` takes
    them. count joint-space samples (seed pool_seed) are kept where at
    least min_visible of the target's points lie image_margin px inside
    the image, the target faces the camera within max_view_angle degrees
    and lies within distance (lo, hi) metres; n of them are chosen
    D-optimally on the pixel Jacobian (seed: the search's; 1 as the
    command line's). gap: score the design against its visible pool's
    certified bound (``report["gap"]``, ``report["d_efficiency"]``; about
    a second: a pose's pixel rows are cut to their rank, 6). pixel_noise:
    the detected points' σ (px); the report then also predicts the true
    error at it (``predicted_error_mm``), and `CameraDesign.how_many`
    uses it. line_of_sight: keep only configurations whose rays from the
    camera to the points are not blocked by the robot's collision
    geometry (meshes found beside the URDF or in package_dirs), on with
    any of self_collision (srdf), floor or obstacles (``"box:…"`` in the
    base frame, or the tree's root with camera_link), which also remove
    the colliding samples (``report["collision_removed"]``)."""

def extract(
    bag: _Path,
    robot: Robot,
    *,
    joints: str = "/joint_states",
    points: Optional[str] = None,
    poses: Optional[str] = None,
    tf: Optional[str] = None,
    time_offset: Optional[float] = None,
    max_offset: float = 10.0,
    rest_speed: float = 0.005,
    rest_min: float = 0.5,
    settle: float = 0.2,
    design: Optional[_Path] = None,
    design_tolerance: float = 0.01,
    progress: Optional[Callable[[str, int, Optional[int], Optional[str]], Any]] = None,
) -> Any:
    """Reads a ROS 2 bag (a rosbag2 folder, or one ``.mcap`` or ``.db3``
    file) as ``activecal extract BAG --out FILE`` does: one row per rest of
    the joints of ``joints`` (every joint slower than ``rest_speed`` rad/s
    for ``rest_min`` s or longer), its joint values and measurement averaged
    after ``settle`` s. The measurement is one of ``points`` (a
    ``PointStamped`` topic), ``poses`` (``PoseStamped`` or
    ``TransformStamped``) or ``tf`` (``"PARENT:CHILD"`` of ``/tf``).
    ``time_offset``: the clock offset (s, the measurement's stamp minus the
    joints'), estimated from the moves within ``±max_offset`` s when None.
    ``design``: the design file the run followed (each rest matched to its
    pose within ``design_tolerance`` rad or m). Returns a pandas DataFrame
    with the CSV's columns (the joints, ``x1, y1, z1``, for poses ``qw1,
    qx1, qy1, qz1``; radians, metres), the extraction's report (rests and
    the reasons some were left out, the clock offset, the scatter) in
    ``attrs["report"]``."""
