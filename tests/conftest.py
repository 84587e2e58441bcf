import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("HEAVECOMP_SHARED", ROOT.parent / "shared"))


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    """../shared beside the checkout (CI has it there)."""
    assert SHARED.is_dir(), f"shared/ folder not found at {SHARED} (set HEAVECOMP_SHARED)"
    return SHARED


@pytest.fixture
def paper_a_toml(tmp_path) -> Path:
    from heavecomp.params import dumps, paper_a

    p = tmp_path / "paper_a.toml"
    p.write_text(dumps(paper_a()))
    return p
