"""simulate: CLI outputs, excitations (sine ramp, JONSWAP Hs/Tp, heave from file) and bad heave data."""

import json

import numpy as np
import pytest

from heavecomp.errors import InputError
from heavecomp.params import dumps, paper_a
from heavecomp.simulate import excitation, simulate

from _cli import run as run_cli


_cli = run_cli  # in this process (tests/_cli.py): what the command writes or refuses


def test_cli_simulate_writes_contract_outputs(paper_a_toml, tmp_path):
    out = tmp_path / "run"
    r = _cli("simulate", str(paper_a_toml), "--duration", "60", "--out", str(out), "--rate", "10")
    assert r.returncode == 0, r.stderr
    header = (out / "timeseries.csv").read_text().splitlines()[0].split(",")
    assert header[:5] == ["t", "heave", "stroke", "pressure", "wob"]
    assert {"stroke_velocity", "friction", "tension"} <= set(header)
    data = np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1)
    assert data.shape[0] == 601 and np.allclose(np.diff(data[:, 0]), 0.1)
    m = json.loads((out / "metrics.json").read_text())
    for k in ("wob_mean", "wob_std", "wob_min", "wob_max", "wob_p2p", "stick_fraction"):
        assert np.isfinite(m[k])
    assert m["wob_p2p"] == pytest.approx(np.ptp(data[data[:, 0] >= 24.0, 4]), rel=1e-6)
    assert (out / "wob.png").stat().st_size > 10_000


def test_sine_ramp_starts_at_rest():
    h = excitation.sine(1.0, 12.0, 24.0, 60.0, 0.005)
    assert h.z[0] == 0 and h.dz[0] == 0
    # derivatives consistent with the displacement (finite differences)
    np.testing.assert_allclose(np.gradient(h.z, 0.005)[10:-10], h.dz[10:-10], atol=2e-5)
    np.testing.assert_allclose(np.gradient(h.dz, 0.005)[10:-10], h.ddz[10:-10], atol=2e-4)


@pytest.mark.parametrize("hs,tp,seed", [(2.0, 12.0, 0), (4.0, 9.0, 3)])
def test_jonswap_matches_requested_hs_tp(hs, tp, seed):
    h = excitation.jonswap(hs, tp, 3.3, seed, 0.0, 3600.0, 0.05)
    hs_g, tp_g = excitation.spectral_hs_tp(h.z, 0.05)
    assert hs_g == pytest.approx(hs, rel=0.03)
    assert tp_g == pytest.approx(tp, rel=0.05)
    np.testing.assert_allclose(np.gradient(h.z, 0.05)[5:-5], h.dz[5:-5], atol=0.02 * np.std(h.dz))
    # seeds give different but equally valid seas
    h2 = excitation.jonswap(hs, tp, 3.3, seed + 1, 0.0, 3600.0, 0.05)
    assert not np.allclose(h.z, h2.z)


def test_heave_from_file_equals_sine(tmp_path):
    t = np.arange(0, 130.0, 0.1)
    z = excitation.sine(1.0, 12.0, 24.0, 130.0, 0.1).z
    (tmp_path / "heave.csv").write_text("t,heave\n" + "\n".join(f"{a:.3f},{b:.12g}" for a, b in zip(t, z)))
    p_file = paper_a().replace(heave={"kind": "file", "path": "heave.csv", "amplitude": None, "period": None,
                                      "ramp": None})
    f = tmp_path / "p.toml"
    f.write_text(dumps(p_file))
    from heavecomp.params import load
    res_file = simulate(load(f), 120.0)
    res_sine = simulate(paper_a(), 120.0)
    # the spline through 10 Hz samples reproduces the analytic sine run to within 1 kN of WOB
    assert np.max(np.abs(res_file["wob"] - res_sine["wob"])) < 1e3


@pytest.mark.parametrize("content,fragment", [
    ("t,heav\n0,0\n1,0\n2,0\n3,0\n", "missing column 'heave'"),
    ("t,heave\n0,0\n1,0\n1,0.1\n2,0\n3,0\n", "column 't', row 4: time not strictly increasing"),
    ("t,heave\n0,0\n1,nan\n2,0\n3,0\n", "column 'heave', row 3: missing or non-finite value"),
    ("t,heave\n0,0\n1,x\n2,0\n3,0\n", "column 'heave', row 3: not a number: 'x'"),
    ("t,heave\n0,0\n1,1500\n2,0\n3,0\n", "column 'heave': excursions over 50 m"),
])
def test_bad_heave_file(tmp_path, content, fragment):
    (tmp_path / "h.csv").write_text(content)
    p = paper_a().replace(heave={"kind": "file", "path": str(tmp_path / "h.csv"), "amplitude": None,
                                 "period": None, "ramp": None})
    with pytest.raises(InputError) as ei:
        simulate(p, 2.0)
    assert fragment in str(ei.value) and "\n" not in str(ei.value)
    f = tmp_path / "p.toml"
    f.write_text(dumps(p))
    r = _cli("simulate", str(f), "--duration", "2", "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and fragment in r.stderr and "Traceback" not in r.stderr


def test_duration_beyond_heave_record(tmp_path):
    with pytest.raises(InputError, match="exceeds the heave record"):
        simulate(paper_a(), 100.0, heave=(np.arange(0, 50.0, 0.5), np.zeros(100)))
