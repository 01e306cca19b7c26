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
Wrong input raises ``activecal.Error`` naming the argument.
"""

from ._activecal import (
    Calibration,
    Design,
    Error,
    Pool,
    Robot,
    __version__,
    calibrate,
    pool,
    select,
)

__all__ = [
    "Calibration",
    "Design",
    "Error",
    "Pool",
    "Robot",
    "__version__",
    "calibrate",
    "pool",
    "select",
]
