"""Shared set-up: the repository's paths and the paper's study, loaded once."""

from pathlib import Path

import pytest

import ttalloc

#: The repository's root (this file is python/tests/conftest.py).
ROOT = Path(__file__).resolve().parents[2]
PAPER_STUDY = ROOT / "studies" / "gyrowheel-2017.toml"
TABLE4_SHEET = ROOT / "studies" / "tolerances" / "table4.toml"


@pytest.fixture(scope="session")
def paper() -> ttalloc.Study:
    return ttalloc.load_study(PAPER_STUDY)
