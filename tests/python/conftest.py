"""Shared fixtures: the real recordings in ../shared/data (tests skip without them), and the
disk the generated sequences take given back as the tests go."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def shared_data_dir() -> Path | None:
    env = os.environ.get("FARLIO_SHARED_DATA")
    p = Path(env) if env else REPO.parent / "shared" / "data"
    return p if p.is_dir() else None


@pytest.fixture
def shared_data() -> Path:
    p = shared_data_dir()
    if p is None:
        pytest.skip("../shared/data is absent")
    return p


@pytest.fixture(scope="module", autouse=True)
def _free_module_disk(request, tmp_path_factory):
    """A generated sequence takes up to 2.5 GB (30 s of racetrack, three LiDARs): the temporary
    folders a test module made are removed when the module ends, unless one of its tests failed
    (kept for inspection). With pytest's tmp_path_retention_policy "failed" (pyproject.toml) a
    passing test's own folder goes at once, so the suite never holds more than one module's data."""
    base = tmp_path_factory.getbasetemp()
    before = set(base.iterdir())
    failed_before = request.session.testsfailed
    yield
    if request.session.testsfailed == failed_before:
        for path in set(base.iterdir()) - before:
            shutil.rmtree(path, ignore_errors=True)
