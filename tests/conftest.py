from pathlib import Path
import subprocess
import sys

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """The measured data shipped inside the package (heavecomp/data, see its README)."""
    from heavecomp.data import ROOT as DATA

    return DATA


@pytest.fixture
def paper_a_toml(tmp_path) -> Path:
    from heavecomp.params import dumps, paper_a

    p = tmp_path / "paper_a.toml"
    p.write_text(dumps(paper_a()))
    return p


@pytest.fixture
def diagnose_cli(tmp_path):
    """``heavecomp diagnose CSV --params TOML --out <tmp>/o [extra...]`` in a fresh interpreter (the
    user's command: exit code and stderr as a shell sees them)."""

    def run(csv, params, *extra):
        return subprocess.run([sys.executable, "-m", "heavecomp.cli", "diagnose", str(csv), "--params", str(params),
                               "--out", str(tmp_path / "o"), *extra], capture_output=True, text=True)

    return run
