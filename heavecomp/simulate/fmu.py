"""``heavecomp export-fmu``: the CMC of a parameter file as a co-simulation FMU (FMI 3.0).

The FMU is packed by ``pythonfmu3`` (``pip install 'heavecomp[fmu]'``): its slave is a short Python
class (:data:`SLAVE`) that steps :class:`heavecomp.simulate.cosim.CoSimulator`, the project's own
exact stick-slip stepper with the file's plant effects; the parameter file travels inside the FMU
(``resources/cmc.toml``).  Variables:

| variable | causality | unit | what |
|---|---|---|---|
| ``time`` | independent | s | |
| ``heave`` | input | m | platform heave z_h (relative to its first value) |
| ``heave_velocity``, ``heave_acceleration`` | input | m/s, m/s^2 | the heave's rates (an MRU measures them), read when ``heave_rates`` |
| ``heave_rates`` | parameter (fixed) | - | false (default): the heave alone, extrapolated over a step from its last four values; true: the rates are connected, the heave over a step is the quintic through this and the last (z, dz, ddz) |
| ``u_active`` | input (with ``[active]`` only) | N | active-cylinder force, held over a step, clipped to u_max |
| ``wob``, ``stroke``, ``pressure``, ``friction``, ``stroke_velocity``, ``tension`` | output | N, m, Pa, N, m/s, N | the plant's channels at the step's end |

Where it runs: the FMU's binary (pythonfmu3's wrapper, Linux x86-64 and Windows x86-64) embeds a
Python interpreter, ``libpython3.X`` of the Python it finds (or the one already running, as in
``fmpy``), which must have ``heavecomp`` and its dependencies installed (numpy, numba, scipy, ...);
pythonfmu3 itself is packed into the FMU.  The stepper compiles on its first use in that Python
(numba's cache then keeps it).  The FMU saves no state (``canGetAndSetFMUState`` false): a master
that rolls back steps cannot use it.
"""

from __future__ import annotations

import logging
import shutil
import tempfile
from pathlib import Path

import numpy as np

from heavecomp.errors import InputError
from heavecomp.params import dumps, load
from heavecomp.simulate import excitation
from heavecomp.simulate.core import default_dt, simulate
from heavecomp.simulate.cosim import OUTPUTS, CoSimulator

log = logging.getLogger(__name__)

#: the FMU's model name (its modelIdentifier and binary name)
MODEL = "HeavecompCMC"

SLAVE = '''"""heavecomp's CMC as a co-simulation slave (written by `heavecomp export-fmu`; needs heavecomp installed)."""
from pathlib import Path

from pythonfmu3 import Boolean, Fmi3Causality, Fmi3Slave, Fmi3Variability, Float64

ACTIVE = {active}
OUTPUTS = {outputs!r}


class {model}(Fmi3Slave):
    author = "heavecomp export-fmu"
    description = "Crown-mounted compensator with exact stick-slip (heavecomp), parameters in resources/cmc.toml"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        from heavecomp.params import load
        from heavecomp.simulate.cosim import CoSimulator

        self._sim = CoSimulator(load(Path(self.resources) / "cmc.toml"))
        self.time = 0.0
        self.heave = 0.0
        self.heave_velocity = 0.0
        self.heave_acceleration = 0.0
        self.heave_rates = False
        self.u_active = 0.0
        for k, v in self._sim.outputs.items():
            setattr(self, k, v)
        self.register_variable(Float64("time", causality=Fmi3Causality.independent, variability=Fmi3Variability.continuous))
        self.register_variable(Float64("heave", causality=Fmi3Causality.input, start=0.0,
                                       description="platform heave z_h [m]"))
        self.register_variable(Float64("heave_velocity", causality=Fmi3Causality.input, start=0.0,
                                       description="heave velocity dz_h/dt [m/s] (read when heave_rates)"))
        self.register_variable(Float64("heave_acceleration", causality=Fmi3Causality.input, start=0.0,
                                       description="heave acceleration d2z_h/dt2 [m/s2] (read when heave_rates)"))
        self.register_variable(Boolean("heave_rates", causality=Fmi3Causality.parameter,
                                       variability=Fmi3Variability.fixed, start=False,
                                       description="true: heave_velocity and heave_acceleration are connected"))
        if ACTIVE:
            self.register_variable(Float64("u_active", causality=Fmi3Causality.input, start=0.0,
                                           description="active-cylinder force [N]"))
        for k, unit in OUTPUTS.items():
            self.register_variable(Float64(k, causality=Fmi3Causality.output, description=f"{{k}} [{{unit}}]"))

    def do_step(self, current_time, step_size):
        rates = (self.heave_velocity, self.heave_acceleration) if self.heave_rates else (None, None)
        out = self._sim.step(current_time, step_size, self.heave, self.u_active, *rates)
        for k, v in out.items():
            setattr(self, k, v)
        self.time = current_time + step_size
        return True
'''


def export_fmu(params_path, out) -> Path:
    """Write the co-simulation FMU of the parameter file ``params_path`` to ``out``.

    Parameters
    ----------
    params_path : str or Path
        The CMC parameter file (its ``[[effects]]`` plant effects and ``[active]`` table are carried).
    out : str or Path
        The ``.fmu`` file written.

    Returns
    -------
    Path
        ``out``.

    Raises
    ------
    InputError
        pythonfmu3 missing, a bad parameter file, or an effect an FMU cannot carry (one line).
    """
    try:
        from pythonfmu3.builder import FmuBuilder
    except ImportError:
        raise InputError("export-fmu needs pythonfmu3: pip install 'heavecomp[fmu]'") from None
    params = load(params_path)
    CoSimulator(params)  # refuses what an FMU cannot carry, before anything is written
    out = Path(out)
    with tempfile.TemporaryDirectory(prefix="heavecomp_fmu_") as tmp:
        tmp = Path(tmp)
        script = tmp / f"{MODEL}.py"
        script.write_text(SLAVE.format(model=MODEL, active="active" in params.extra and
                                       params.extra["active"] is not None, outputs=OUTPUTS))
        res = tmp / "res"
        res.mkdir()
        toml = res / "cmc.toml"
        toml.write_text(dumps(params))
        built = FmuBuilder.build_FMU(script, dest=tmp / "build", project_files=[toml])
        out.parent.mkdir(parents=True, exist_ok=True)
        shutil.move(str(built), str(out))
    log.info("FMU written: %s", out)
    return out


def validate(fmu, params, duration: float = 300.0, *, rate: float = 20.0, rates: bool = True, hs: float = 1.5,
             tp: float = 10.0, seed: int = 3) -> dict:
    """Simulate ``fmu`` in ``fmpy`` with the heave of a ``simulate`` run and compare the WOB.

    The heave is a JONSWAP record (``hs``, ``tp``, ``seed``; no fade-in, whose end would put a kink in the
    heave acceleration that no master passes on), relative to its first value; ``simulate`` runs on it
    (the same samples, spaced h/2) and the FMU gets it at ``rate`` [Hz], with its rates when ``rates``.

    Parameters
    ----------
    fmu : str or Path
        The FMU (:func:`export_fmu` of ``params``' file).
    params : CMCParams
        The parameter set it was exported from.
    duration : float [s]
        Simulated time.
    rate : float [Hz]
        Communication (and output) rate.
    rates : bool
        Connect ``heave_velocity`` and ``heave_acceleration`` (``heave_rates`` true).
    hs, tp : float [m], [s]
        The JONSWAP sea state of the platform heave.
    seed : int
        Its random phases.

    Returns
    -------
    dict
        ``max_error_over_std``, ``rms_error_over_std`` (the WOB of the FMU against ``simulate``'s, over the
        standard deviation of ``simulate``'s WOB), ``wob_std_N``, ``n_stick`` of ``simulate``, ``samples``.
    """
    try:
        import fmpy
    except ImportError:
        raise InputError("validating an FMU needs fmpy: pip install 'heavecomp[fmu]'") from None

    h = default_dt(params, rate)
    sp = 0.5 * h
    raw = excitation.jonswap(hs, tp, 3.3, seed, 0.0, duration, sp)
    heave = excitation.HeaveSamples(sp, raw.z - raw.z[0], raw.dz, raw.ddz, {"kind": "jonswap"})
    ref = simulate(params, duration, rate=rate, heave=heave)
    every = int(round(1.0 / (rate * sp)))
    t = ref["t"]
    k = np.arange(t.size) * every
    cols = [("time", t), ("heave", heave.z[k])]
    if rates:
        cols += [("heave_velocity", heave.dz[k]), ("heave_acceleration", heave.ddz[k])]
    signal = np.array(list(zip(*(c for _n, c in cols))), dtype=[(n, float) for n, _c in cols])
    res = fmpy.simulate_fmu(str(fmu), stop_time=float(t[-1]), step_size=1.0 / rate, output_interval=1.0 / rate,
                            input=signal, output=["wob"], start_values={"heave_rates": bool(rates)})
    n = min(len(res), t.size)
    w, wr = np.asarray(res["wob"][:n]), ref["wob"][:n]
    std = float(np.std(wr))
    err = np.abs(w - wr)
    return {"max_error_over_std": float(err.max() / std), "rms_error_over_std": float(np.sqrt(np.mean(err ** 2)) / std),
            "wob_std_N": std, "n_stick": int(ref.stats["n_stick"]), "samples": int(n)}
