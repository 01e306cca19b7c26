"""activecal from Python: choose the poses to measure for kinematic robot
calibration (D-optimal design), then calibrate from the measurements.

    import activecal
    robot = activecal.Robot.from_urdf("ur5.urdf", tip="tool0",
                                      marker=("tool0", (0.0, 0.0, 0.1)))
    design = activecal.select(robot, 30, noise=50e-6)
    # ... move the arm to each row of design.q, read the tracker ...
    cal = activecal.calibrate(robot, design.q, points)
    cal.write_urdf("calibrated.urdf")

Lengths are metres, angles radians (joint values, limits, estimates), the
residuals and predicted errors millimetres and degrees (their keys say so).
Arrays are float64 NumPy arrays; anything NumPy reads as one is accepted.
Every error is an ``activecal.Error``: ``InputError`` (a wrong argument,
its name first, or a wrong value in a file, with its place; also a
``ValueError``), ``FileError`` (a file not read or written, or an output
that exists when a writer is given ``overwrite=False``; also an
``OSError``), ``ResourceError`` (too large, with the figure),
``ComputationError`` (cannot be done on these inputs) or ``InternalError``
(a defect: please report it); the last three are also ``RuntimeError``.
Writers replace an existing file by default. Ctrl-C stops a long call.
``Robot``, ``Pool``, ``Design`` and ``Calibration`` pickle (as the call
that made them, made again on loading).
"""

from ._activecal import (
    Calibration,
    CameraCalibration,
    CameraDesign,
    ContactCalibration,
    Design,
    ComputationError,
    Error,
    FileError,
    InputError,
    InternalError,
    Page,
    Pool,
    ResourceError,
    Robot,
    __version__,
    bound,
    calibrate,
    calibrate_camera,
    calibrate_contacts,
    detect,
    evaluate,
    extract,
    gap,
    pool,
    select,
    select_camera,
)

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
