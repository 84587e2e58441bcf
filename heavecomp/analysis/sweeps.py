"""Eigenfrequencies vs the wave band: drill-string length x formation stiffness.

Paper A (section 4, last paragraph): the CMC's mechanical eigenfrequency lies
above the wave frequency, so cylinder force disturbances reach the bit almost
unfiltered; a longer, softer string or a softer formation would either resonate
with the waves or filter them.  :func:`eigenfrequency_map` answers that for a
rig: it sweeps the string length (stiffness EA/L, mass from the pipe) and the
formation stiffness and returns both undamped eigenfrequencies of the linear
2-DOF model and the transmissibility at wave periods.

Drill string (documented assumption, :class:`DrillPipe`): 5" 19.5 lb/ft drill
pipe, steel E = 210 GPa, tube-body steel area 3.40e-3 m^2 (OD 127.0 mm, ID
108.6 mm), nominal mass 29.0 kg/m; BHA 27.1 t.  The string is one spring
k_ds = EA/L; the lower mass is m_b = m_BHA + m_pipe/3 (Rayleigh: a uniform rod
fixed at the top end moving with its free end contributes a third of its mass
to the fundamental mode).  With L = 300 m this gives k_ds = 2.38 MN/m and
m_b = 30.0 t, close to the paper-A set (2.08 MN/m, 30 t).  The lumped model is
valid while the string's own first axial mode (fixed-fixed, omega = pi c / L,
c = sqrt(E/rho) ~ 5.1 km/s: 5.4 rad/s at 3000 m) stays above the modes it
predicts; the map reports that frequency too.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from heavecomp.analysis.frequency import WAVE_BAND, freqresp_batch
from heavecomp.analysis.linear import batch_matrices


@dataclasses.dataclass(frozen=True)
class DrillPipe:
    """Drill-pipe and BHA properties for the length sweep (SI).

    Defaults: 5" 19.5 lb/ft (grade E/S) drill pipe, OD 127.0 mm, ID 108.6 mm.

    Attributes
    ----------
    youngs_modulus : float [Pa]  (steel, 210 GPa)
    steel_area : float [m^2]     (pi/4 (0.127^2 - 0.1086^2) = 3.40e-3)
    mass_per_length : float [kg/m]  (19.5 lb/ft nominal = 29.0 kg/m)
    bha_mass : float [kg]        (27.1 t: 30 t lumped lower mass at 300 m, as the paper-A set)
    mass_fraction : float [-]    (share of the pipe mass lumped into m_b; 1/3, Rayleigh)
    """

    youngs_modulus: float = 210e9
    steel_area: float = math.pi / 4 * (0.1270 ** 2 - 0.1086 ** 2)
    mass_per_length: float = 19.5 * 1.48816
    bha_mass: float = 27.1e3
    mass_fraction: float = 1.0 / 3.0

    def stiffness(self, length):
        """Axial stiffness k_ds = E A / L [N/m] for length L [m]."""
        return self.youngs_modulus * self.steel_area / np.asarray(length, dtype=float)

    def lower_mass(self, length):
        """Lumped lower mass m_b = m_BHA + fraction * m' L [kg]."""
        return self.bha_mass + self.mass_fraction * self.mass_per_length * np.asarray(length, dtype=float)

    def axial_mode(self, length):
        """First axial mode of the string alone, fixed-fixed: omega = pi sqrt(E A / m') / L [rad/s]."""
        c = math.sqrt(self.youngs_modulus * self.steel_area / self.mass_per_length)
        return math.pi * c / np.asarray(length, dtype=float)


def eigenfrequency_map(params, lengths, formation_stiffness, *, pipe: DrillPipe | None = None,
                       wave_periods=(5.0, 8.0, 12.0, 16.0, 20.0)) -> dict:
    """Undamped eigenfrequencies and wave-period transmissibility over (L, k_F).

    Parameters
    ----------
    params : CMCParams
        Compensator (k_gas, M_c, area), damping values; drill string and
        formation stiffness are replaced by the sweep.
    lengths : array_like (nL,) [m]
    formation_stiffness : array_like (nK,) [N/m]
    pipe : DrillPipe, optional
    wave_periods : sequence [s]

    Returns
    -------
    dict of ndarray
        ``lengths`` (nL,), ``formation_stiffness`` (nK,), ``string_stiffness``
        (nL,), ``lower_mass`` (nL,), ``omega`` (nL, nK, 2) undamped natural
        frequencies [rad/s, ascending], ``in_wave_band`` (nL, nK, 2) bool,
        ``k_eff_static`` (nL, nK) eq. 14 [N/m], ``wave_periods`` (nP,),
        ``transmissibility`` (nL, nK, nP) |k_eff(omega)|/k_eff(0) at the wave
        periods (frictionless, with the set's damping), ``string_axial_mode``
        (nL,) [rad/s].
    """
    pipe = pipe or DrillPipe()
    L = np.asarray(lengths, dtype=float)
    kF = np.asarray(formation_stiffness, dtype=float)
    kd = pipe.stiffness(L)[:, None]
    mb = pipe.lower_mass(L)[:, None]
    c, ds, fo = params.compensator, params.drill_string, params.formation
    kg, Mc = c.gas_stiffness, c.moving_mass
    # undamped 2-DOF: M ddq + K q = 0; eigenvalues of M^-1 K in closed form (2x2)
    k11 = (kg + kd) / Mc
    k22 = (kd + kF[None, :]) / mb
    k12k21 = kd * kd / (Mc * mb)
    tr, det = k11 + k22, k11 * k22 - k12k21
    disc = np.sqrt(np.maximum(tr * tr / 4 - det, 0.0))
    omega = np.sqrt(np.stack([tr / 2 - disc, tr / 2 + disc], axis=-1))
    lo, hi = WAVE_BAND
    A, B, C, D = batch_matrices(gas_stiffness=kg, moving_mass=Mc, lower_mass=mb, string_stiffness=kd,
                                formation_stiffness=kF[None, :], area=params.area, string_damping=ds.damping,
                                formation_damping=fo.damping)
    wp = np.asarray(wave_periods, dtype=float)
    H = freqresp_batch(A, B, C, D, np.concatenate([[0.0], 2 * np.pi / wp]))[..., 0, 0, :]
    k_static = 1.0 / (1.0 / kg + 1.0 / kd + 1.0 / kF[None, :])
    return {
        "lengths": L, "formation_stiffness": kF, "string_stiffness": kd[:, 0], "lower_mass": mb[:, 0],
        "omega": omega, "in_wave_band": (omega >= lo) & (omega <= hi), "k_eff_static": k_static,
        "wave_periods": wp, "transmissibility": np.abs(H[..., 1:]) / np.abs(H[..., :1]),
        "string_axial_mode": pipe.axial_mode(L),
    }
