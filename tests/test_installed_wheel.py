"""`make test` tests what users install: the abi3 wheel, installed into a fresh virtual
environment (SOFTARM_WHEEL_VENV) with no Rust toolchain on the PATH. These checks fail that
run if softarm were imported from the checkout's python/ (or an editable install) instead of
the wheel in site-packages, or if cargo could be found. Outside that run they skip."""

from __future__ import annotations

import json
import os
import shutil
import sys
import sysconfig
from importlib.metadata import distribution
from pathlib import Path

import pytest

import softarm
import softarm._core

WHEEL_VENV = os.environ.get("SOFTARM_WHEEL_VENV")
ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.skipif(
    not WHEEL_VENV, reason="only in the wheel run of `make test` (SOFTARM_WHEEL_VENV unset)"
)


def test_softarm_is_imported_from_the_wheel_venv_site_packages() -> None:
    assert WHEEL_VENV is not None
    assert Path(sys.prefix).resolve() == Path(WHEEL_VENV).resolve()
    site = {Path(sysconfig.get_paths()[key]).resolve() for key in ("purelib", "platlib")}
    package = Path(softarm.__file__).resolve().parent
    assert package.parent in site, f"softarm imported from {package}, not {site}"
    assert Path(softarm._core.__file__).resolve().parent == package
    assert not package.is_relative_to(ROOT / "python")


def test_installed_from_an_abi3_wheel_file_not_editable() -> None:
    dist = distribution("softarm")
    direct_url = json.loads(dist.read_text("direct_url.json") or "{}")
    assert direct_url.get("url", "").endswith(".whl"), direct_url
    assert "archive_info" in direct_url and "dir_info" not in direct_url, direct_url
    wheel = (dist.read_text("WHEEL") or "").splitlines()
    tags = [line for line in wheel if line.startswith("Tag:")]
    assert tags and all("-abi3-" in tag for tag in tags), tags


def test_no_rust_toolchain_on_the_path() -> None:
    assert shutil.which("cargo") is None
    assert shutil.which("rustc") is None
