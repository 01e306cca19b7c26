"""activecal's PEP 517 build backend: maturin's, refusing to start without
Rust's ``cargo`` on the PATH.

maturin's own backend downloads a Rust toolchain (through ``puccinialin``,
about 1.2 GB) when it finds no ``cargo``; building activecal also needs
OpenBLAS's development files, which no download brings, so a user would wait
for the toolchain and then fail on the link. This wrapper stops at once with
what to install instead, and tells maturin never to install Rust
(``MATURIN_NO_INSTALL_RUST``). With ``cargo`` present every hook is
maturin's, unchanged.
"""

from __future__ import annotations

import os
import shutil
from typing import Any, Mapping, Optional

NO_CARGO = (
    "activecal: building the package from source needs Rust's `cargo` on the PATH "
    "(https://rustup.rs; a stable Rust of 2025 or later), a C linker and OpenBLAS "
    "(Debian/Ubuntu: apt-get install libopenblas-dev libgfortran-12-dev pkg-config). "
    "No `cargo` was found on the PATH, and no toolchain is downloaded. "
    "Install Rust and run the command again, or install a prebuilt activecal wheel."
)

os.environ["MATURIN_NO_INSTALL_RUST"] = "1"


class CargoNotFound(RuntimeError):
    """Raised by every hook when `cargo` is not on the PATH."""


def _maturin():
    """maturin's backend, once `cargo` is known to be there."""
    if shutil.which("cargo") is None:
        raise CargoNotFound(NO_CARGO)
    import maturin

    return maturin


def get_requires_for_build_wheel(config_settings: Optional[Mapping[str, Any]] = None) -> list:
    return _maturin().get_requires_for_build_wheel(config_settings)


def get_requires_for_build_sdist(config_settings: Optional[Mapping[str, Any]] = None) -> list:
    return _maturin().get_requires_for_build_sdist(config_settings)


def prepare_metadata_for_build_wheel(
    metadata_directory: str, config_settings: Optional[Mapping[str, Any]] = None
) -> str:
    return _maturin().prepare_metadata_for_build_wheel(metadata_directory, config_settings)


def build_wheel(
    wheel_directory: str,
    config_settings: Optional[Mapping[str, Any]] = None,
    metadata_directory: Optional[str] = None,
) -> str:
    return _maturin().build_wheel(wheel_directory, config_settings, metadata_directory)


def build_sdist(sdist_directory: str, config_settings: Optional[Mapping[str, Any]] = None) -> str:
    return _maturin().build_sdist(sdist_directory, config_settings)


def build_editable(
    wheel_directory: str,
    config_settings: Optional[Mapping[str, Any]] = None,
    metadata_directory: Optional[str] = None,
) -> str:
    return _maturin().build_editable(wheel_directory, config_settings, metadata_directory)
