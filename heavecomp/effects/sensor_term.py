"""``sensor_term``: the open search's misreading of one channel carried as a reading correction.

The gap diagnosis' channel search (:func:`heavecomp.diagnosis.components.channel_search`) fits generic
misreadings of one channel, functions of the channel's own reading ``y`` (:func:`features`), to every
equation that reads it; its term ``m = sum_k c_k f_k(y_meas)`` (``verdict.discovered``: ``channel``,
``features``, ``coefficients`` and the feature constants, ``levels``) is what the reading adds to the
true value: ``y_meas = y + m``.  This effect carries it as a correction of how a log is read, kept apart
from the plant (like ``sensor_gain`` / ``sensor_offset``): :meth:`SensorTerm.undo` gives ``y = y_meas -
m(y_meas)`` (explicit: the features are functions of the reading); :meth:`SensorTerm.measure` reads a
true channel back (``y_meas = y + m(y_meas)``, solved by fixed-point iteration).

=====================  ==========================================  =====================  ================
feature (search name)  f(y_meas)                                   coefficient            constants
=====================  ==========================================  =====================  ================
``abs``                ``|y - center|``                            ``c_abs`` [-]          ``center``
``sq``                 ``(y - center)^2``                          ``c_sq`` [1/unit]      ``center``
``top``                ``y >= top_level``                          ``c_top`` [unit]       ``top_level``
``bottom``             ``y <= bottom_level``                       ``c_bottom`` [unit]    ``bottom_level``
``top_motion``         ``(y >= top_level) (z_h + s - motion_top)``  ``c_top_motion``       ``motion_top``
                                                                   [unit/m]
``bottom_motion``      the same at the bottom level                ``c_bottom_motion``    ``motion_bottom``
``play<k>``            ``play(y, play_width) - y``                 ``c_play`` [-]         ``play_width``
=====================  ==========================================  =====================  ================

The ``*_motion`` features read the string top's position ``z_h + s`` (heave plus stroke, [m]): they need
the log's heave and stroke (:func:`heavecomp.effects.spec.correct` gives them).  Not a diagnosis
candidate and not in the registry's library composition.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import ChannelEffect
from heavecomp.errors import ParameterError
from heavecomp.params.core import q

#: the feature names of the channel search this effect carries -> its coefficient parameter
COEFFICIENT = {"abs": "c_abs", "sq": "c_sq", "top": "c_top", "bottom": "c_bottom", "top_motion": "c_top_motion",
               "bottom_motion": "c_bottom_motion", "play": "c_play"}
#: coefficients that read the string top's motion (z_h + s)
MOTION = ("c_top_motion", "c_bottom_motion")
#: fixed-point iterations of :meth:`SensorTerm.measure` (the reading's features of the reading)
ITERATIONS = 8


def play(y, width):
    """The textbook play (backlash) operator of width ``width``: the output holds until the input has
    moved half the width past it (Prandtl-Ishlinskii's elementary hysteron).

    Parameters
    ----------
    y : numpy.ndarray [unit]
        Input series.
    width : float [unit]
        Width of the play.
    """
    h = 0.5 * width
    out = np.empty_like(y)
    o = float(y[0])
    for i, x in enumerate(y.tolist()):
        o = min(max(o, x - h), x + h)
        out[i] = o
    return out


def base_name(feature: str) -> str:
    """The feature's kind (``play0.1`` -> ``play``; the others are their own).

    Parameters
    ----------
    feature : str
        A channel-search feature name (without its ``channel:`` prefix).
    """
    return "play" if feature.startswith("play") else feature


def feature(name, y, lv, motion=None):
    """One misreading feature of the reading ``y`` with the constants ``lv`` (``center``, ``top_level``,
    ``bottom_level``, ``motion_top``, ``motion_bottom``, ``play_width``).

    Parameters
    ----------
    name : str
        Feature kind (a key of :data:`COEFFICIENT`).
    y : numpy.ndarray [unit of the channel]
        The reading.
    lv : dict
        The feature constants [unit of the channel, m].
    motion : numpy.ndarray [m], optional
        The string top's position ``z_h + s`` (the ``*_motion`` features).
    """
    y = np.asarray(y, float)
    if name == "abs":
        return np.abs(y - lv["center"])
    if name == "sq":
        d = y - lv["center"]
        return d * d
    if name in ("top", "top_motion"):
        at = (y >= lv["top_level"]).astype(float)
    elif name in ("bottom", "bottom_motion"):
        at = (y <= lv["bottom_level"]).astype(float)
    elif name == "play":
        return play(y, lv["play_width"]) - y
    else:
        raise ParameterError(f"sensor_term: unknown feature {name!r}")
    if not name.endswith("_motion"):
        return at
    return at * (np.asarray(motion, float) - lv["motion_top" if name == "top_motion" else "motion_bottom"])


class SensorTerm(ChannelEffect):
    """y_meas = y + m(y_meas), m a sum of the channel search's generic misreadings (module docstring)."""

    name = "sensor_term"
    #: a file may leave out every parameter the term does not use (0)
    optional = ("center", "top_level", "bottom_level", "motion_top", "motion_bottom", "play_width",
                *COEFFICIENT.values())

    @dataclass(frozen=True)
    class Params:
        c_abs: float = q(0.0, "-", bounds=(-1e3, 1e3), symbol="c_abs", doc="coefficient of |y - center|")
        c_sq: float = q(0.0, "1/unit of the channel", bounds=(-1e6, 1e6), symbol="c_sq",
                        doc="coefficient of (y - center)^2")
        c_top: float = q(0.0, "unit of the channel", bounds=(-1e9, 1e9), symbol="c_top",
                         doc="reading added at the top level (y >= top_level)")
        c_bottom: float = q(0.0, "unit of the channel", bounds=(-1e9, 1e9), symbol="c_bot",
                            doc="reading added at the bottom level (y <= bottom_level)")
        c_top_motion: float = q(0.0, "unit of the channel/m", bounds=(-1e12, 1e12), symbol="c_tm",
                                doc="reading added at the top level per m of string-top motion")
        c_bottom_motion: float = q(0.0, "unit of the channel/m", bounds=(-1e12, 1e12), symbol="c_bm",
                                   doc="reading added at the bottom level per m of string-top motion")
        c_play: float = q(0.0, "-", bounds=(-1e3, 1e3), symbol="c_play", doc="coefficient of play(y, w) - y")
        center: float = q(0.0, "unit of the channel", bounds=(-1e12, 1e12), symbol="y_c",
                          doc="the reading's centre (its median in the diagnosed log)")
        top_level: float = q(0.0, "unit of the channel", bounds=(-1e12, 1e12), symbol="y_top",
                             doc="level at and above which the reading is at its top limit")
        bottom_level: float = q(0.0, "unit of the channel", bounds=(-1e12, 1e12), symbol="y_bot",
                                doc="level at and below which the reading is at its bottom limit")
        motion_top: float = q(0.0, "m", bounds=(-1e3, 1e3), symbol="z_top",
                              doc="mean string-top position z_h + s while at the top limit")
        motion_bottom: float = q(0.0, "m", bounds=(-1e3, 1e3), symbol="z_bot",
                                 doc="mean string-top position z_h + s while at the bottom limit")
        play_width: float = q(0.0, "unit of the channel", bounds=(0.0, 1e12), symbol="w", doc="width of the play")

    @classmethod
    def null(cls, plant):
        return {f.name: 0.0 for f in cls.fields()}

    def term(self, y, motion=None):
        """The misreading m(y) [unit of the channel] of the reading ``y`` (``motion``: z_h + s [m], needed
        by nonzero ``*_motion`` coefficients)."""
        v = self.values
        if motion is None and any(v[c] for c in MOTION):
            raise ParameterError(f"effect {self.name} on {self.channel}: its *_motion terms read the string top's "
                                 "motion z_h + s: they need the heave and stroke with the reading")
        m = np.zeros(np.shape(y))
        for f, c in COEFFICIENT.items():
            if v[c]:
                m = m + v[c] * feature(f, y, v, motion)
        return m

    def undo_reading(self, t, y, cols=None):
        """The true channel from the reading ``y`` (:meth:`undo`), the string top's motion (heave +
        stroke) read from the log's ``cols`` when it has both.

        Parameters
        ----------
        t : numpy.ndarray [s]
            Times of the reading (unused: the correction is memoryless).
        y : numpy.ndarray [unit of the channel]
            The reading.
        cols : dict, optional
            The log's channels by name.
        """
        motion = None
        if cols is not None and "heave" in cols and "stroke" in cols:
            motion = np.asarray(cols["heave"], dtype=float) + np.asarray(cols["stroke"], dtype=float)
        return self.undo(y, motion)

    def undo(self, y, motion=None):
        """The true channel from the reading ``y``: ``y - m(y)``."""
        y = np.asarray(y, float)
        return y - self.term(y, motion)

    def measure(self, t, tg, y, motion=None):
        """The recorded channel at times ``t`` from the true ``y`` on the grid ``tg``: ``y_meas = y +
        m(y_meas)``, by :data:`ITERATIONS` fixed-point iterations from ``y``."""
        y = np.interp(np.asarray(t, float), np.asarray(tg, float), np.asarray(y, float))
        out = y.copy()
        for _ in range(ITERATIONS):
            out = y + self.term(out, motion)
        return out


EFFECT = SensorTerm
