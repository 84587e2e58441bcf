"""heave_reference's lever arm: a heave measured at a lever arm L times a logged pitch angle
(z_meas = z_crown + L sin(pitch), the validation's truth law :func:`heavecomp.benchmark.truth.heave_reference.heave_lever_arm`)
is mapped back to the crown's heave, fitted by the diagnosis, refused where no angle exists, and a bad
pitch column is one line (exit 2)."""


import numpy as np
import pytest

from heavecomp.benchmark.truth import heave_reference as T
from heavecomp.diagnosis.data import heave_samples, load_run, MeasuredRun
from heavecomp.effects.heave_reference import HeaveReference
from heavecomp.errors import DataError, ParameterError
from heavecomp.params import dumps, paper_a
from heavecomp.simulate import excitation

P = paper_a()


def _lever_heave(L=8.0, dur=120.0, dt=0.02):
    """Crown heave (JONSWAP), a synthetic pitch and the heave measured at lever arm L (truth law)."""
    hs = excitation.jonswap(2.5, 10.0, 3.3, 5, 20.0, dur, dt)
    t = hs.t
    th = T.synthetic_pitch(t, 0.008, 10.0, 11)
    zm = T.heave_lever_arm(t, {"heave": hs.z}, L, th)["heave"]
    return t, hs.z, zm, th


def test_lever_arm_maps_the_measured_heave_back_to_the_crown():
    t, z, zm, th = _lever_heave()
    h = 0.01
    n = int((t[-1] - 1.0) / h)
    crown = heave_samples(MeasuredRun(t, {"heave": z}), h, n)
    meas = heave_samples(MeasuredRun(t, {"heave": zm, "pitch": th}), h, n)
    seen = HeaveReference(lever_arm=8.0).transform(meas)
    plain = HeaveReference().transform(meas)
    mid = slice(2000, -2000)  # away from the pre-filter's edges
    for k in ("z", "dz", "ddz"):
        a, b, c = getattr(seen, k)[mid], getattr(crown, k)[mid], getattr(plain, k)[mid]
        if k == "z":  # each relative to its own reference: compare the motion
            a, b, c = a - a.mean(), b - b.mean(), c - c.mean()
        err, err0 = np.std(a - b), np.std(c - b)
        assert err < 0.02 * err0, (k, err, err0)


def test_no_angle_fits_two_parameters_and_a_lever_arm_needs_one():
    t, z, zm, th = _lever_heave(dur=30.0)
    with_angle = heave_samples(MeasuredRun(t, {"heave": zm, "pitch": th}), 0.01, 2000)
    without = heave_samples(MeasuredRun(t, {"heave": zm}), 0.01, 2000)
    assert HeaveReference.for_input(with_angle).n_params() == 4  # g, t_d, L and the MRU's high-pass corner
    assert HeaveReference.for_input(without).n_params() == 3
    with pytest.raises(ParameterError, match="lever_arm"):
        HeaveReference(lever_arm=5.0).transform(without)


def test_casadi_model_refuses_a_lever_arm():
    from heavecomp.effects.model import heave_map

    assert heave_map([HeaveReference(scale=0.9)]) == (0.9, 0.0)
    with pytest.raises(ParameterError, match="heave_reference.*lever_arm"):
        heave_map([HeaveReference(lever_arm=5.0)])


def _write(path, t, cols, header):
    rows = [",".join(header)]
    for i in range(len(t)):
        rows.append(",".join(str(v) for v in [t[i]] + [cols[c][i] for c in header[1:]]))
    path.write_text("\n".join(rows) + "\n")
    return path


def _good(tmp_path, pitch):
    t = np.arange(600) * 0.05
    z = 0.5 * np.sin(2 * np.pi * t / 10)
    cols = {"heave": z, "stroke": -0.9 * z, "pressure": P.p0 + 1e5 * z,
            "wob": P.operating_point.wob_setpoint + 2e4 * z, "pitch": pitch(t)}
    return _write(tmp_path / "r.csv", t, cols, ("t", "heave", "stroke", "pressure", "wob", "pitch"))


def test_pitch_in_degrees_is_declared_or_refused(tmp_path):
    f = _good(tmp_path, lambda t: 0.8 * np.sin(2 * np.pi * t / 9))  # degrees
    run = load_run(f, P, units={"pitch": "deg"})
    assert np.max(np.abs(run["pitch"])) == pytest.approx(np.deg2rad(0.8), rel=1e-3)
    with pytest.raises(DataError, match="'pitch'.*degrees"):
        load_run(f, P)


@pytest.mark.parametrize("bad", ["degrees", "text"])
def test_cli_bad_pitch_column_exit_2_one_line(tmp_path, bad, diagnose_cli):
    if bad == "degrees":
        f = _good(tmp_path, lambda t: 2.0 * np.sin(2 * np.pi * t / 9))
    else:
        f = _good(tmp_path, lambda t: np.where(t > 10, "n/a?", "0.01"))
    toml = tmp_path / "nom.toml"
    toml.write_text(dumps(P))
    r = diagnose_cli(f, toml)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "'pitch'" in lines[0], r.stderr


CASE = dict(label="heave_reference", seed=20913, category="named", duration=120.0, rate=50.0, sea="jonswap",
            params="paper_a", noise=1.0, start=0.0, variant="lever_arm", near=False, second=None, pair_cut=0.0)
#: heave_reference and the candidates a heave at a lever arm was confused with
CANDIDATES = ["heave_reference", "string_damping", "sensor_gain", "sensor_delay", "parameter_mismatch"]


@pytest.fixture(scope="module")
def lever_case():
    from heavecomp.benchmark import Case, generate

    return generate(Case(**CASE))


@pytest.mark.slow
def test_diagnosis_fits_the_lever_arm_from_a_logged_pitch(lever_case):
    from heavecomp.diagnosis.estimator import GapDiagnoser

    tr = lever_case
    L = tr.truth["parameters"]["heave_reference"]["lever_arm"]
    d = GapDiagnoser(tr.nominal, CANDIDATES, n_jobs=2).fit(tr.to_run())
    v = d.verdict_
    assert v["effect"] == "heave_reference" and v["confidence"] == "high", v
    got = d.candidates_[0]["parameters"]["lever_arm"]
    assert got == pytest.approx(L, rel=0.15), (got, L)


@pytest.mark.slow
def test_without_its_pitch_column_no_confident_wrong_verdict(lever_case):
    from heavecomp.diagnosis.data import check_run
    from heavecomp.diagnosis.estimator import GapDiagnoser

    tr = lever_case
    cols = {k: v for k, v in tr.columns.items() if k != "pitch"}
    d = GapDiagnoser(tr.nominal, CANDIDATES, n_jobs=2).fit(check_run(tr.t, cols, params=tr.nominal))
    v = d.verdict_
    assert "lever_arm" not in d.candidates_[[r["effect"] for r in d.candidates_].index("heave_reference")]["parameters"]
    assert v["effect"] == "heave_reference" or v["confidence"] != "high", v
