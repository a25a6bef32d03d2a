"""Shared fixtures: the repository, the `learn` binary (for round trips with the CLI), scratch folders."""

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def learn_binary() -> Path:
    path = Path(os.environ.get("LEARN_BINARY", ROOT / "target" / "debug" / "learn")).resolve()
    assert path.is_file(), f"{path}: build the workspace first (make build)"
    return path


@pytest.fixture
def run_learn(learn_binary):
    def run(*args, cwd=None):
        result = subprocess.run(
            [str(learn_binary), "--quiet", *map(str, args)], cwd=cwd, capture_output=True, text=True
        )
        assert result.returncode == 0, result.stderr
        return result

    return run
