"""The module under test is the build's (build/python, or ANGIOSYNTH_PYTHON_DIR), the program beside it."""

import os
import pathlib
import sys

SOURCE = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("ANGIOSYNTH_BUILD", SOURCE / "build"))
sys.path.insert(0, str(BUILD / "python"))

import pytest  # noqa: E402


@pytest.fixture(scope="session")
def source():
    return SOURCE


@pytest.fixture(scope="session")
def program():
    exe = BUILD / "angiosynth"
    assert exe.is_file(), f"{exe}: build the program first (bash scripts/build.sh)"
    return str(exe)
