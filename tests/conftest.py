from pathlib import Path

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
