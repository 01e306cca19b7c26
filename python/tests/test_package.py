"""The package as installed: its version is the crate's, its metadata
complete, and its source tree's build backend refuses at once without
cargo (maturin's own would download a Rust toolchain)."""

import importlib.metadata
import os
import re
import sys
from pathlib import Path

import pytest

import activecal
from conftest import REPO


def crate_version(manifest):
    """The [package] version of a Cargo.toml, read as text (tomllib is
    3.11+)."""
    text = manifest.read_text()
    package = text.split("[package]", 1)[1].split("\n[", 1)[0]
    return re.search(r'^version\s*=\s*"([^"]+)"', package, re.M).group(1)


def test_the_version_is_the_crates():
    crate = crate_version(REPO / "python" / "Cargo.toml")
    assert activecal.__version__ == crate
    assert crate_version(REPO / "Cargo.toml") == crate
    assert importlib.metadata.version("activecal") == crate


def test_the_metadata_is_complete():
    meta = importlib.metadata.metadata("activecal")
    assert meta["Name"] == "activecal"
    assert meta["Requires-Python"] == ">=3.9"
    assert meta["License-Expression"] == "MIT OR Apache-2.0"
    assert sorted(meta.get_all("License-File")) == ["LICENSE-APACHE", "LICENSE-MIT"]
    assert meta["Description-Content-Type"].startswith("text/markdown")
    assert "pip install ./python" in meta.get_payload()
    classifiers = meta.get_all("Classifier")
    for v in ("3.9", "3.10", "3.11", "3.12", "3.13"):
        assert f"Programming Language :: Python :: {v}" in classifiers
    assert "Typing :: Typed" in classifiers
    files = {str(f) for f in importlib.metadata.files("activecal")}
    assert "activecal/__init__.pyi" in files and "activecal/py.typed" in files
    licences = [f for f in files if "licenses/LICENSE-" in f]
    assert len(licences) == 2, licences
    assert not any("build_backend" in f for f in files)


def test_the_installed_package_is_tested_when_asked():
    # scripts/test-python sets ACTIVECAL_INSTALLED: the package imported is
    # then the wheel's, not the source tree's python/activecal.
    if not os.environ.get("ACTIVECAL_INSTALLED"):
        pytest.skip("not run against an installed wheel")
    where = Path(activecal.__file__).resolve()
    assert "site-packages" in where.parts, where
    assert REPO / "python" not in where.parents, where


def test_the_build_backend_refuses_without_cargo(monkeypatch):
    monkeypatch.syspath_prepend(str(REPO / "python" / "build_backend"))
    sys.modules.pop("activecal_build", None)
    import activecal_build

    monkeypatch.setenv("PATH", str(Path(sys.executable).parent))
    for hook, args in (
        (activecal_build.get_requires_for_build_wheel, ()),
        (activecal_build.prepare_metadata_for_build_wheel, ("unused",)),
        (activecal_build.build_wheel, ("unused",)),
        (activecal_build.build_sdist, ("unused",)),
    ):
        with pytest.raises(activecal_build.CargoNotFound, match="needs Rust's `cargo` on the PATH"):
            hook(*args)
    # maturin's own backend is told never to install Rust.
    assert os.environ["MATURIN_NO_INSTALL_RUST"] == "1"
    backend = (REPO / "python" / "pyproject.toml").read_text()
    assert 'build-backend = "activecal_build"' in backend
    assert 'backend-path = ["build_backend"]' in backend
