"""Zero-phase FIR filtering and differentiation (paper B's friction measurement method).

Paper B (Fujita et al. 1999, "Friction force measurement"): the friction is
obtained from the equation of motion using pressures and displacement; the
displacement is differentiated twice, and "since differentiation amplifies the
noise ... a FIR low pass filter was used.  The raw data was filtered forward and
backwards in time to eliminate the filter phase shift."

This module does exactly that: a linear-phase FIR low-pass (``scipy.signal.firwin``,
Hamming window) applied with ``scipy.signal.filtfilt`` (forward and backward:
zero phase, squared magnitude response), central differences for the
derivatives, and the filter applied again after each differentiation.

It is the package's one home for zero-phase filtering (issue 11.5).  Three low-passes, one
signature ``(x, fs, cutoff, ...)``, named by how they differ:

- :func:`hamming_zero_phase`: paper B's Hamming-window FIR (:func:`differentiate`,
  :func:`friction_from_motion`);
- :func:`flat_zero_phase`: the diagnosis' heave and channel pre-filter, a Kaiser-window FIR
  whose pass band is flat to 0.04 % after the forward-backward pass;
- :func:`butterworth_zero_phase`: the identification's forward-backward Butterworth.

No function here skips filtering silently: a cut-off at or above the Nyquist frequency, or a
signal too short for the filter, raises :class:`~heavecomp.errors.InputError`, except
:func:`flat_zero_phase`, which returns a channel whose sampling already band-limits it below the
filter unchanged and logs that.
"""

from __future__ import annotations

import logging

import numpy as np

from heavecomp.errors import DataError, InputError
from heavecomp.errors import ParameterError

#: zero-phase FIR low-pass cut-off of a measured heave [Hz] (paper B's method; waves < 0.7 Hz): the diagnosis'
#: replay and ``simulate`` with a heave file pre-process a measured heave the same way
HEAVE_CUTOFF = 0.8

log = logging.getLogger(__name__)

FLAT_TRANSITION = 0.75  #: transition band of :func:`flat_zero_phase` as a fraction of its cut-off [-] (0.5-1.1 Hz for the heave)
FLAT_RIPPLE = 2e-4  #: pass-band ripple of one pass of :func:`flat_zero_phase` [-] (forward-backward: 0.04 %)

def sample_rate(t, *, name: str = "t", rtol: float = 1e-3) -> float:
    """Sampling rate [Hz] of a uniformly sampled time vector ``t`` [s].

    Raises DataError (naming the column) when ``t`` is not strictly increasing or
    not uniform within ``rtol``.

    Parameters
    ----------
    t : array [s]
        Time column, strictly increasing and uniform.
    name : str
        Column name for the error messages.
    rtol : float
        Largest deviation of a step from the median step, relative [-].
    """
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 3:
        raise DataError(f"column {name}: need at least 3 samples")
    if not np.all(np.isfinite(t)):
        raise DataError(f"column {name}: contains NaN or inf")
    dt = np.diff(t)
    if np.any(dt <= 0):
        raise DataError(f"column {name}: time must be strictly increasing (row {int(np.argmax(dt <= 0)) + 1})")
    med = float(np.median(dt))
    if np.max(np.abs(dt - med)) > rtol * med + 1e-12 * abs(t[-1]):
        raise DataError(f"column {name}: sampling is not uniform (steps {dt.min():g} .. {dt.max():g} s); resample first")
    return 1.0 / med


def design_lowpass(fs: float, cutoff: float, numtaps: int | None = None) -> np.ndarray:
    """FIR low-pass taps (Hamming window, linear phase).

    Parameters
    ----------
    fs : float [Hz]
    cutoff : float [Hz]
        -6 dB frequency of one pass (-12 dB after forward-backward filtering).
    numtaps : int, optional
        Odd tap count; default ~ 3.3 fs/cutoff (transition width ~ cutoff).
    """
    from scipy.signal import firwin

    if not (0 < cutoff < 0.5 * fs):
        raise InputError(f"cutoff = {cutoff:g} Hz must lie in (0, fs/2 = {0.5 * fs:g} Hz)")
    if numtaps is None:
        numtaps = int(np.ceil(3.3 * fs / cutoff)) | 1
    numtaps = int(numtaps) | 1
    return firwin(numtaps, cutoff, fs=fs, window="hamming")


def design_flat_lowpass(fs: float, cutoff: float, width: float, ripple: float = 2e-4,
                        max_taps: int | None = None) -> np.ndarray:
    """FIR low-pass taps with a flat pass band (Kaiser window, linear phase).

    Parameters
    ----------
    fs : float [Hz]
    cutoff : float [Hz]
        Centre of the transition band (-6 dB of one pass).
    width : float [Hz]
        Transition band: flat below ``cutoff - width/2``, attenuated above ``cutoff + width/2``.
    ripple : float [-]
        Largest deviation of one pass from 1 in the pass band (and of the gain from 0 in the stop
        band); the forward-backward pass squares the response, so its pass band is flat to
        about ``2 ripple``.
    max_taps : int, optional
        Longest filter allowed (a short signal); the transition band then widens and the
        ripple is what that length gives (``scipy.signal.kaiserord`` inverted), never a silent skip.

    Raises
    ------
    InputError
        When the stop edge ``cutoff + width/2`` is not below ``fs/2``.
    """
    from scipy.signal import firwin, kaiser_beta, kaiserord

    if not (0 < width and 0 < cutoff - 0.5 * width and cutoff + 0.5 * width < 0.5 * fs):
        raise InputError(f"cutoff = {cutoff:g} Hz with a {width:g} Hz transition band must lie in "
                         f"(0, fs/2 = {0.5 * fs:g} Hz)")
    atten = -20.0 * np.log10(ripple)
    numtaps, beta = kaiserord(atten, width / (0.5 * fs))
    if max_taps is not None and numtaps > max_taps:
        numtaps = int(max_taps)
        # the attenuation this length reaches over the same transition band (kaiserord's formula)
        atten = max(21.0, 7.95 + 2.285 * (numtaps - 1) * np.pi * width / (0.5 * fs))
        beta = kaiser_beta(atten)
    numtaps = int(numtaps) | 1
    return firwin(numtaps, cutoff, fs=fs, window=("kaiser", beta))


def filtfilt_fir(x, b) -> np.ndarray:
    """Forward-backward FIR filtering of ``x`` with taps ``b`` (odd extension of 3 filter lengths):
    zero phase, squared magnitude response.

    The signal must be longer than 3 filter lengths; otherwise InputError.

    ``scipy.signal.filtfilt(b, [1.0], x, padtype="odd", padlen=3 * b.size)`` step by step, with the
    FIR's steady-state initial condition in closed form (``zi[k] = sum(b[k+1:])``, what
    ``lfilter_zi`` returns) instead of ``lfilter_zi``'s dense solve, cubic in the number of taps
    (0.14 s per call for a 1 Hz filter at 50 Hz; ``tests/test_signals.py`` pins the two equal).

    Parameters
    ----------
    x : array
        Signal, filtered along its last axis.
    b : array
        FIR taps (e.g. :func:`design_lowpass`).
    """
    from scipy.signal import lfilter
    from scipy.signal._arraytools import odd_ext

    x = np.asarray(x, dtype=float)
    b = np.asarray(b, dtype=float)
    if x.shape[-1] <= 3 * b.size:
        raise InputError(f"signal of {x.shape[-1]} samples is too short for a {b.size}-tap filter: "
                         "raise the cutoff or record longer")
    n = 3 * b.size
    zi = np.cumsum(b[::-1])[::-1][1:] if b.size > 1 else np.zeros(0)
    ext = odd_ext(x, n, axis=-1)
    y, _ = lfilter(b, [1.0], ext, zi=zi * ext[0])
    y, _ = lfilter(b, [1.0], y[::-1], zi=zi * y[-1])
    return y[::-1][n:-n]


def hamming_zero_phase(x, fs: float, cutoff: float, numtaps: int | None = None) -> np.ndarray:
    """Filter ``x`` forward and backward with the Hamming FIR low-pass: no phase shift (paper B).

    The signal must be longer than 3 filter lengths (``filtfilt`` padding);
    otherwise InputError.

    Parameters
    ----------
    x : array
        Signal sampled at ``fs``, filtered along its last axis.
    fs : float [Hz]
        Sampling rate.
    cutoff : float [Hz]
        -6 dB frequency of one pass (:func:`design_lowpass`).
    numtaps : int, optional
        Odd tap count; default ~ 3.3 fs/cutoff.
    """
    x = np.asarray(x, dtype=float)
    b = design_lowpass(fs, cutoff, numtaps)
    if x.shape[-1] <= 3 * b.size:
        raise InputError(f"signal of {x.shape[-1]} samples is too short for a {b.size}-tap filter "
                         f"(cutoff {cutoff:g} Hz at {fs:g} Hz): raise the cutoff or record longer")
    return filtfilt_fir(x, b)


def flat_zero_phase(x, fs: float, cutoff: float, transition: float = FLAT_TRANSITION,
                    ripple: float = FLAT_RIPPLE) -> np.ndarray:
    """Zero-phase FIR low-pass with a flat pass band: :func:`design_flat_lowpass` (Kaiser window,
    transition band ``transition`` x cut-off centred on it, pass-band ripple ``ripple`` per pass) run
    forward and backward (:func:`filtfilt_fir`); the diagnosis' heave and channel pre-filter.

    Below the transition band the response is flat to 2 ``ripple`` (0.04 %): the heave's wave band
    passes unchanged (the Hamming FIR used until 2026-11 amplified 0.1-0.4 Hz by 0.5-1 %).

    When the stop edge lies at or above the Nyquist frequency ``fs/2`` the sampling itself
    band-limits the channel below the filter: the channel is returned unchanged and this is
    logged (documented in ``docs/diagnosis.md``; until 2026-11 the skip was silent).  A signal too
    short for the full filter gets the longest filter it can carry (a wider transition band).

    Parameters
    ----------
    x : array
        Signal sampled at ``fs``, filtered along its last axis.
    fs : float [Hz]
        Sampling rate.
    cutoff : float [Hz]
        Centre of the transition band (-6 dB of one pass).
    transition : float [-]
        Width of the transition band as a fraction of ``cutoff``.
    ripple : float [-]
        Pass-band ripple of one pass.
    """
    width = transition * cutoff
    if cutoff + 0.5 * width >= 0.5 * fs:
        log.info("zero-phase low-pass at %g Hz skipped: sampling at %g Hz already band-limits below %g Hz",
                 cutoff, fs, 0.5 * fs)
        return np.asarray(x, dtype=float)
    x = np.asarray(x, dtype=float)
    b = design_flat_lowpass(fs, cutoff, width, ripple, max_taps=max(3, (x.size - 1) // 3 - 1))
    return filtfilt_fir(x, b)


def butterworth_zero_phase(x, fs: float, cutoff: float, order: int = 4) -> np.ndarray:
    """Forward-backward Butterworth low-pass (zero phase, squared magnitude); the identification's
    filter (Gautier's IDIM-LS, :mod:`heavecomp.identification.filtering`).

    Parameters
    ----------
    x : array
        Signal sampled at ``fs``.
    fs : float, Hz
        Sampling rate.
    cutoff : float, Hz
        -3 dB frequency of the single-pass Butterworth filter (the forward-backward
        pass is -6 dB there).
    order : int
        Butterworth order (the forward-backward pass doubles it).

    Raises
    ------
    ParameterError
        Cut-off outside (0, fs/2) or order < 1.
    """
    import scipy.signal as ss


    if not 0.0 < cutoff < 0.5 * fs:
        raise ParameterError(f"cutoff must be in (0, fs/2) = (0, {0.5 * fs:g}) Hz, got {cutoff:g}")
    if int(order) < 1:
        raise ParameterError(f"order must be a positive integer, got {order}")
    sos = ss.butter(int(order), cutoff, fs=fs, output="sos")
    return ss.sosfiltfilt(sos, np.asarray(x, dtype=float))


def differentiate(t, x, cutoff: float, *, order: int = 2, numtaps: int | None = None, name: str = "x"):
    """Zero-phase filtered derivatives of ``x(t)``.

    Returns ``(x_f, dx/dt, d2x/dt2)`` (for ``order = 2``; ``order = 1`` omits the last),
    each filtered forward-backward with the same FIR low-pass.

    Parameters
    ----------
    t : array [s], uniformly sampled
    x : array
    cutoff : float [Hz]
        -6 dB frequency of one pass of the FIR low-pass (:func:`design_lowpass`).
    order : int
        Number of derivatives, 1 or 2.
    numtaps : int, optional
        Odd tap count; default ~ 3.3 fs/cutoff.
    name : str
        Column name of ``x`` for the error messages.
    """
    fs = sample_rate(t)
    x = np.asarray(x, dtype=float)
    if x.shape != np.shape(t):
        raise DataError(f"column {name}: length {x.size} differs from the time column ({np.size(t)})")
    if not np.all(np.isfinite(x)):
        raise DataError(f"column {name}: contains NaN or inf")
    dt = 1.0 / fs
    xf = hamming_zero_phase(x, fs, cutoff, numtaps)
    out = [xf]
    y = xf
    for _ in range(order):
        y = hamming_zero_phase(np.gradient(y, dt), fs, cutoff, numtaps)
        out.append(y)
    return tuple(out)


def friction_from_motion(t, x, drive_force, mass: float, cutoff: float, *, numtaps: int | None = None) -> dict:
    """Paper B's friction measurement: ``F_f = F_drive - M d2x/dt2``.

    Parameters
    ----------
    t : array [s]
    x : array [m]  displacement (e.g. encoder)
    drive_force : array [N]  pressure force, e.g. ``A (P_a - P_b)``
    mass : float [kg]
    cutoff : float [Hz]  -6 dB frequency of one pass of the FIR low-pass
    numtaps : int, optional  odd tap count; default ~ 3.3 fs/cutoff

    Returns
    -------
    dict with ``velocity`` [m/s], ``acceleration`` [m/s^2], ``friction`` [N]
    (the drive force filtered with the same zero-phase filter, so all terms share
    the same frequency response).
    """
    fs = sample_rate(t)
    F = np.asarray(drive_force, dtype=float)
    if F.shape != np.shape(t):
        raise DataError(f"column drive_force: length {F.size} differs from the time column ({np.size(t)})")
    _, v, a = differentiate(t, x, cutoff, numtaps=numtaps)
    Ff = hamming_zero_phase(F, fs, cutoff, numtaps) - mass * a
    return {"velocity": v, "acceleration": a, "friction": Ff}
