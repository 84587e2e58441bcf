"""A campaign folder is only resumed by the same campaign AND the same plant/stepper source."""

import json

import pytest

from heavecomp.campaign import spec
from heavecomp.campaign.execute import MANIFEST, _check_manifest
from heavecomp.errors import InputError
from heavecomp.simulate.layout import source_hash


def test_manifest_records_physics_and_refuses_other_source(tmp_path):
    camp = spec.default()
    _check_manifest(camp, tmp_path)
    man = json.loads((tmp_path / MANIFEST).read_text())
    assert man["physics"] == f"{source_hash():x}"
    _check_manifest(camp, tmp_path)  # same campaign, same physics: resumable
    man["physics"] = "0"
    (tmp_path / MANIFEST).write_text(json.dumps(man))
    with pytest.raises(InputError, match="another version of the plant/stepper source"):
        _check_manifest(camp, tmp_path)
