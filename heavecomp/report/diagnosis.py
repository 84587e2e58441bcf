"""Diagnosis outputs: ``diagnosis.json`` (contract schema 1), ``report.md`` and the figures."""

from __future__ import annotations

import copy
import json
import math
import re
from pathlib import Path

import numpy as np

from heavecomp.diagnosis import verdict as V
from heavecomp.diagnosis.where import residual_spectrum
from heavecomp.report.figures import _plt, save
from heavecomp.report.scenario import md_table
from heavecomp.report.provenance import _clean, declare_units, stamp, stamp_report
from heavecomp.simulate.core import CHANNEL_UNITS
from heavecomp.effects import CANDIDATES

CH_UNITS = {"wob": ("kN", 1e-3), "stroke": ("mm", 1e3), "pressure": ("kPa", 1e-3)}
#: names of :func:`heavecomp.diagnosis.where.eigenfrequencies`, in its order
MODE_NAMES = ("sliding, low mode (top mass on the gas spring)", "sliding, high mode (lower mass on string and "
              "formation)", "stuck cylinder (lower mass on k_ds + k_F)")


def named_modes(freqs_hz) -> str:
    """Eigenfrequencies sorted by frequency, each named by its mode: ``"0.44 Hz (sliding, ...)"``.

    Parameters
    ----------
    freqs_hz : sequence of float [Hz]
        Eigenfrequencies in the order of :func:`heavecomp.diagnosis.where.eigenfrequencies`.
    """
    names = MODE_NAMES if len(freqs_hz) == len(MODE_NAMES) else [f"mode {i + 1}" for i in range(len(freqs_hz))]
    return ", ".join(f"{f:.2f} Hz ({n})" for f, n in sorted(zip(freqs_hz, names)))


def _effect_units(effect: str, values=None) -> dict:
    """Parameter name -> unit from the effect class's own metadata ({} for an unknown name); for a
    channel effect with its fitted ``values``, "unit of the channel" becomes that channel's SI unit."""

    cls = CANDIDATES.get(effect)
    units = {d["name"]: d["unit"] for d in cls.describe()} if cls is not None else {}
    si = CHANNEL_UNITS.get((values or {}).get("channel"))
    if si:
        units = {k: re.sub(r"unit of the channel( \([^)]*\))?( per s)?", lambda m: si + ("/s" if m.group(2) else ""), u)
                 for k, u in units.items()}
    return units


def _with_unit(name: str, val, sigma=None, units=None) -> str:
    """``name = value ± sigma unit`` for a fitted parameter (``units``: :func:`_effect_units`)."""
    if not isinstance(val, float):
        return f"{name} = {val}"
    u = (units or {}).get(name)
    pm = f" ± {sigma:.2g}" if isinstance(sigma, float) and math.isfinite(sigma) else ""
    return f"{name} = {val:.4g}{pm}" + (f" {u}" if u and u != "-" else "")


def write_json(diag, path) -> Path:
    """Write ``diagnosis.json`` with the unit of every fitted parameter declared where it is made.

    Parameters
    ----------
    diag : GapDiagnoser
        A fitted diagnoser.
    path : str or Path
        The file to write.
    """
    path = Path(path)
    d = copy.deepcopy(diag.to_json())  # the declarations go into the file, not into the diagnoser's own results
    for block in _parameter_blocks(d):  # the effect's own metadata, the channel's unit for a channel effect
        if isinstance(block.get("parameters"), dict) and isinstance(block.get("effect"), str):
            units = _effect_units(V.member(block), block["parameters"])  # a family's law: its member's units
            own = {k: u for k, u in units.items() if k in block["parameters"]}
            if own:
                declare_units(block["parameters"], own)
                block["parameter_units"] = own  # beside the values: a key name cannot pick the wrong unit
    path.write_text(json.dumps(_clean(d), indent=2) + "\n")
    return path


def _parameter_blocks(d: dict) -> list:
    """The blocks of a ``diagnosis.json`` dict that carry an ``effect`` and its fitted ``parameters``."""
    v = d.get("verdict", {})
    blocks = [v, *d.get("candidates", [])]
    if isinstance(v.get("second_effect"), dict):
        blocks.append(v["second_effect"])
    blocks += [c for c in v.get("second_candidates", []) or [] if isinstance(c, dict)]
    return blocks


def fig_where(diag):
    """Residual over stroke velocity x acceleration (nominal replay), coloured by |WOB residual|.

    Parameters
    ----------
    diag : heavecomp.diagnosis.GapDiagnoser
        A fitted diagnoser (its ``verdict_``, ``where_``, ``traces_``, ``split_``, ...).
    """
    plt = _plt()
    tr = diag.traces_
    t = tr["t"]
    v = tr["stroke_velocity"]
    a = np.gradient(v, t)
    ch = diag.where_.get("channel", "wob")  # the primary channel: WOB, else the first the log has
    unit, sc = CH_UNITS[ch]
    r = tr["nominal"][ch] - tr["measured"][ch]
    ok = np.isfinite(r) & (t >= diag.split_["settle"])
    fig, (ax, axb) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [1.6, 1]})
    # binned, not one dot per sample: a long run overplots a scatter into a solid blot
    vv, aa = v[ok] * 1e3, a[ok]
    lim_v = np.percentile(np.abs(vv), 99.5) * 1.05 or 1.0
    lim_a = np.percentile(np.abs(aa), 99.5) * 1.05 or 1.0
    hb = ax.hexbin(vv, aa, C=np.abs(r[ok]) * sc, reduce_C_function=np.mean, gridsize=(45, 25), mincnt=1,
                   cmap="viridis", extent=(-lim_v, lim_v, -lim_a, lim_a))
    ax.set_xlim(-lim_v, lim_v)
    ax.set_ylim(-lim_a, lim_a)
    fig.colorbar(hb, ax=ax, label=f"mean |{ch} residual| per bin [{unit}]")
    ax.set_xlabel("stroke velocity v [mm/s]")
    ax.set_ylabel("stroke acceleration [m/s²]")
    ax.set_title(f"Where: {ch} residual over (v, dv/dt) of the nominal replay", fontsize=10)
    ax.grid(alpha=0.3)
    w = diag.where_
    keys = list(w["regimes"]) + list(w["bands"])
    vals = [w["regimes"][k] for k in w["regimes"]] + [w["bands"][k] for k in w["bands"]]
    cols = ["tab:red"] * len(w["regimes"]) + ["tab:blue"] * len(w["bands"])
    axb.barh(range(len(keys)), vals, color=cols)
    axb.set_yticks(range(len(keys)), [k.replace("_", " ") for k in keys], fontsize=8)
    axb.invert_yaxis()
    axb.set_xlabel(f"share of squared {ch} residual [-]")
    axb.set_title("by regime (red) and frequency band (blue)", fontsize=10)
    axb.grid(alpha=0.3, axis="x")
    fig.tight_layout()
    return fig


def fig_spectra(diag):
    """Residual spectra per channel before (nominal) and after (best candidate), with the band edges.

    Parameters
    ----------
    diag : heavecomp.diagnosis.GapDiagnoser
        A fitted diagnoser (its ``verdict_``, ``where_``, ``traces_``, ``split_``, ...).
    """
    plt = _plt()
    tr = diag.traces_
    t = tr["t"]
    fig, axs = plt.subplots(1, 3, figsize=(13, 3.8))
    for ax, c in zip(axs, ("wob", "stroke", "pressure")):
        unit, sc = CH_UNITS[c]
        if c not in tr["measured"]:  # a channel the log does not have
            _not_measured(ax, c)
            continue
        y = tr["measured"][c]
        ok = np.isfinite(y) & (t >= diag.split_["settle"])
        for label, key, col in (("nominal", "nominal", "tab:red"), (f"with {tr['best_effect']}", "best", "tab:green"))[
                :1 if diag.verdict_["effect"] == "none" else 2]:  # none: no fitted effect to show
            f, S = residual_spectrum(t[ok], (tr[key][c][ok] - y[ok]) * sc)
            ax.loglog(f[1:], S[1:], color=col, lw=1, label=label)
        for k, (lo, hi) in diag.where_["band_edges_hz"].items():
            if lo:
                ax.axvline(lo, color="0.6", lw=0.6, ls="--")
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel(f"residual PSD [{unit}²/Hz]")
        ax.set_title(f"{c} residual spectrum", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.suptitle("Residual spectra (dashed: band edges below-wave | wave | resonance | above)", fontsize=10)
    fig.tight_layout()
    return fig


def fig_overlay(diag, span=40.0):
    """Measured vs nominal vs best candidate on held-out data around the worst held-out segment.

    Parameters
    ----------
    diag : heavecomp.diagnosis.GapDiagnoser
        A fitted diagnoser (its ``verdict_``, ``where_``, ``traces_``, ``split_``, ...).
    span : float [s]
        Time shown, around the worst held-out segment.
    """
    plt = _plt()
    tr = diag.traces_
    t = tr["t"]
    t0 = diag.split_["validate"][0]
    segs = [s for s in diag.where_["segments"] if s[0] >= t0] or [[t0, t0 + span]]
    c0 = 0.5 * (segs[0][0] + segs[0][1])
    lo = max(t0, c0 - span / 2)
    hi = min(t[-1], lo + span)
    m = (t >= lo) & (t <= hi)
    fig, axs = plt.subplots(4, 1, figsize=(11, 9), sharex=True)
    show = diag.verdict_["effect"] != "none"  # none: the nominal is the answer, no candidate is drawn
    ax = axs[3]
    ch = diag.where_.get("channel", "wob")  # the primary channel: WOB, else the first the log has
    unit_p, sc_p = CH_UNITS[ch]
    yw = tr["measured"][ch][m]
    ax.plot(t[m], (tr["nominal"][ch][m] - yw) * sc_p, color="tab:red", lw=1.0, label="nominal − measured")
    if show:
        ax.plot(t[m], (tr["best"][ch][m] - yw) * sc_p, color="tab:green", lw=1.0,
                label=f"with {tr['best_effect']} − measured")
    ax.set_ylabel(f"{ch} residual [{unit_p}]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    for ax, c in zip(axs, ("wob", "stroke", "pressure")):
        unit, sc = CH_UNITS[c]
        if c in tr["measured"]:
            ax.plot(t[m], tr["measured"][c][m] * sc, color="0.4", lw=0.8, label="measured")
        else:
            ax.set_title(f"{c}: not measured (model only)", fontsize=8, loc="left")
        ax.plot(t[m], tr["nominal"][c][m] * sc, color="tab:red", lw=1.1, label="nominal replay")
        if show:
            ax.plot(t[m], tr["best"][c][m] * sc, color="tab:green", lw=1.1, ls="--", label=f"with {tr['best_effect']}")
        ax.set_ylabel(f"{c} [{unit}]")
        ax.grid(alpha=0.3)
    axs[0].legend(fontsize=8, loc="upper right")
    axs[-1].set_xlabel("time t [s]")
    axs[0].set_title(overlay_title(diag.verdict_, tr["best_effect"]), fontsize=10)
    fig.tight_layout()
    return fig


def _not_measured(ax, c) -> None:
    """An empty panel for a channel the log does not have."""
    ax.text(0.5, 0.5, f"{c}: not measured", ha="center", va="center", transform=ax.transAxes, fontsize=10)
    ax.set_xticks([])
    ax.set_yticks([])


def overlay_title(v, best) -> str:
    """The overlay's title, by what the verdict ``v`` says (``best``: the best candidate drawn).

    Parameters
    ----------
    v : dict
        The verdict (``diagnosis.json``'s ``verdict``).
    best : str
        The best candidate's effect name (the one drawn).
    """
    eff = v["effect"]
    if eff == "none":
        return "Held-out data, verdict none: the nominal replay agrees with the measurement within the noise"
    if eff in ("inconclusive", "discovered"):
        return (f"Held-out data, verdict {eff}: the best named candidate ({best}, dashed) explains only "
                f"{100 * v.get('explained', 0.0):.0f} % of the gap")
    return (f"Before/after on held-out data: {V.label(v)} shrinks the {v.get('shrink_channel', 'wob')} gap by "
            f"{100 * v['shrink']:.0f} % (confidence {v['confidence']})")


def _initial_state_lines(diag) -> list:
    """The replay's estimated initial state (issue 12, start anywhere), one line."""
    st = getattr(diag, "initial_", None)
    if st is None:
        return []
    assumed = set(getattr(st, "assumed", ()) or ())
    # a channel the log lacks is assumed at its operating-point value, never reported as if measured
    stroke = ("stroke 0 m and at rest (assumed: no stroke channel)" if "stroke" in assumed else
              f"stroke {st.stroke:+.4f} m, stroke velocity {st.stroke_velocity:+.4f} m/s "
              f"({'stuck' if st.stuck else 'sliding'})")
    wob = "WOB W_0 (assumed: no WOB channel)" if "wob" in assumed else f"WOB {st.wob / 1e3:.1f} kN"
    return [f"\nReplay started from the state estimated from the first {st.window:g} s: {stroke}, lower mass "
            f"{1e3 * st.lower_displacement:+.2f} mm, {wob}, heave reference "
            f"{st.heave_reference:+.4f} m ({'at rest at the operating point' if st.at_rest else 'not at rest'})."]


def _levels_line(where) -> str:
    """Offset and slow trend of the residual, and the bands of the rest, as shares of the whole."""
    lv = where.get("levels")
    if not lv:
        return ""
    return ("Of the whole squared residual: " + ", ".join(f"{k.replace('_', ' ')} {100 * x:.0f} %" for k, x in lv.items())
            + " (offset and slow trend counted before the bands).")


def _component_lines(diag) -> list:
    """The components table (schema 2 ``where.components``) and the open search's discovered term."""
    rows = diag.where_.get("component_table")
    if not rows:
        return []
    v = diag.verdict_
    out = ["Each model equation evaluated on the measured signals alone (measured minus nominal); the share of "
           "the gap is each component's mean square above its noise and above what the same computation makes "
           "of the nominal model's own replay.", "",
           md_table(["component", "share [-]", "gap / noise [-]", "residual rms", "noise rms", "unit", "equation"],
                    [[r["component"], f"{r['share']:.2f}", f"{r['gap_to_noise']:.2f}", f"{r['rms']:.4g}",
                      f"{r['noise']:.4g}", r["unit"], ", ".join(r["equations"]).replace("_", " ")]
                     if r.get("observable", True) else
                     [r["component"], "not observable", "-", "-", "-", r["unit"],
                      ", ".join(r["equations"]).replace("_", " ")] for r in rows])]
    hidden = [r["component"] for r in rows if not r.get("observable", True)]
    if hidden:
        out += ["", "Not observable with this log's channels (every equation that carries them reads a channel "
                    "the log does not have): " + ", ".join(c.replace("_", " ") for c in hidden)
                + ". Their share is 0 by construction, not by measurement; the replay still sees them."]
    if v.get("component"):
        out += ["", f"The gap lives in: **{v['component'].replace('_', ' ')}**."]
    ct = v.get("component_table")
    if ct:  # the verdict's component and the table's largest share differ: why (verdict._table_check)
        out += ["", f"The table puts {100 * ct['share']:.0f} % of the gap in {ct['largest'].replace('_', ' ')} and "
                    f"{100 * ct['verdict_share']:.0f} % in {v['component'].replace('_', ' ')}, the verdict's "
                    f"component: {ct['reason']}."]
    d = v.get("discovered")
    if d:
        out += ["", f"Open search (sparse regression on the {d['component'].replace('_', ' ')} residual, "
                    f"{d.get('unit', '')}): `{d['term']}` (features {', '.join(d['features'])}), held-out shrink of "
                    f"that residual {d['shrink']:.2f}. A suggestion, not a named effect."]
    return out


def _skipped_lines(diag) -> list:
    """Candidates the pre-screen did not replay (their component shows no gap)."""
    sk = [c for c in diag.candidates_ if c.get("skipped")]
    if not sk:
        return []
    return ["", "Not replayed (pre-screen, equation error): " + "; ".join(
        f"`{c['effect']}` ({c['skipped'].split(': ', 1)[-1]})" for c in sk) + "."]


def _not_fitted_lines(diag) -> list:
    """Candidates not fitted because the log's sensor set cannot detect them (no computable residual)."""
    nf = getattr(diag, "undetectable_", [])
    if not nf:
        return []
    return ["", f"Not fitted (this sensor set, {', '.join(diag.sensors_)}, cannot detect them: no residual "
                "computable from its channels carries them): " + ", ".join(f"`{n}`" for n in nf) + "."]


def write_report(diag, out_dir, *, title="Sim-to-real gap diagnosis") -> dict:
    """Write diagnosis.json, report.md and where.png / spectra.png / overlay.png into ``out_dir``.

    Parameters
    ----------
    diag : heavecomp.diagnosis.GapDiagnoser
        A fitted diagnoser (its ``verdict_``, ``where_``, ``traces_``, ``split_``, ...).
    out_dir : str or pathlib.Path
        Folder written (created if missing).
    title : str
        Title of report.md.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_json(diag, out / "diagnosis.json")
    save(fig_where(diag), out / "where.png", dpi=90)
    save(fig_spectra(diag), out / "spectra.png", dpi=90)
    save(fig_overlay(diag), out / "overlay.png", dpi=90)
    v = diag.verdict_
    g = diag.gap_
    pc = diag.where_.get("channel", "wob")
    pu, ps = CH_UNITS[pc]
    group = diag.verdict_group()
    tested = "distinguishable" in v
    laws = v.get("group_laws") or {}  # a family of laws in the group: its law
    named = (f"**Verdict: one of {', '.join(f'`{m}`' + (f' (law: {laws[m]})' if m in laws else '') for m in group)}** "
             f"({'this log' if tested else 'this sensor set'} cannot tell them apart; `{V.label(v)}` "
             f"{'leads' if tested else 'fitted best'})" if group and len(group) > 1 else f"**Verdict: `{V.label(v)}`**")
    lines = [f"# {title}", "",
             f"{named} (confidence {v['confidence']}{', the group' + chr(39) + 's' if group and len(group) > 1 else ''}); "
             f"held-out shrink of the {v.get('shrink_channel', 'wob')} residual {v['shrink']:.2f}."]
    if v.get("note"):
        lines.append(f"\n{v['note']}.")
    lines += _distinguish_lines(v)
    if v.get("parameters"):
        unc = v.get("uncertainty", {})
        lines.append("\nFitted parameters: " + ", ".join(
            _with_unit(k, val, unc.get(k), _effect_units(V.member(v), v["parameters"])) for k, val in v["parameters"].items()) + ".")
    if v.get("second_effect"):
        se = v["second_effect"]
        lines.append(f"\nSecond effect: `{se['effect']}` adds {100 * se['added_explained']:.0f} % of the held-out "
                     f"gap when fitted jointly with the first.")
    elif v.get("second_candidates"):
        sc = v["second_candidates"][0]
        if sc["added_explained"] > 0.05:
            lines.append(f"\nPossible second effect: `{sc['effect']}` adds {100 * sc['added_explained']:.0f} % of the "
                         "held-out gap when fitted jointly with the first — below the 10 % needed to name it.")
    for w in getattr(diag, "warnings_", []):
        lines.append(f"\n> data: {w}")
    lines += _initial_state_lines(diag)
    lines += ["", "## Gap (nominal replay vs measurement, after the settling window)", "",
              md_table(["channel", "unit", "rms", "nrmse [-]", "rms held-out", "noise floor"],
                       [[c, CH_UNITS[c][0], f"{g['channels'][c]['rms'] * CH_UNITS[c][1]:.4g}",
                         f"{g['channels'][c]['nrmse']:.3f}",
                         f"{g['channels'][c]['rms_validate'] * CH_UNITS[c][1]:.4g}",
                         f"{g['channels'][c]['noise_floor'] * CH_UNITS[c][1]:.4g}"]
                        for c in ("wob", "stroke", "pressure") if c in g["channels"]]),
              "", "## Where", "",
              f"Share of the squared {diag.where_.get('channel', 'wob')} residual by regime: " + ", ".join(
                  f"{k.replace('_', ' ')} {100 * x:.0f} %" for k, x in diag.where_["regimes"].items()) + ".",
              "By band: " + ", ".join(f"{k.replace('_', ' ')} {100 * x:.0f} %" for k, x in diag.where_["bands"].items())
              + f". Eigenfrequencies: {named_modes(diag.where_['eigenfrequencies_hz'])}.",
              _levels_line(diag.where_),
              "Largest in: " + ", ".join(f"{a:.1f}-{b:.1f} s" for a, b in diag.where_["segments"]) + ".",
              "", "![where](where.png)", "", "![spectra](spectra.png)", "",
              "## Which: every candidate, fitted on the fit part, scored on the held-out part", "",
              md_table(["effect", "explained [-]", "score [-]", f"{pc} rms before [{pu}]", f"{pc} rms after [{pu}]",
                        "wob shrink [-]", "stroke shrink [-]", "pressure shrink [-]", "parameters"],
                       [[c["effect"], f"{c['explained']:.2f}", f"{c['score']:.2f}", f"{c['rms_before'] * ps:.4g}",
                         f"{c['rms_after'] * ps:.4g}",
                         *(f"{c['channels'][k]['shrink']:.2f}" if k in c["channels"] else "not measured"
                           for k in ("wob", "stroke", "pressure")),
                         ", ".join(_with_unit(k, val, units=_effect_units(c["effect"], c["parameters"]))
                                   for k, val in c["parameters"].items())]
                        for c in diag.candidates_ if not c.get("skipped")]),
              *_skipped_lines(diag), *_not_fitted_lines(diag),
              "", "## Where, by model component (equation error)", "", *_component_lines(diag),
              "", f"Split: fit {diag.split_['fit'][0]:.0f}-{diag.split_['fit'][1]:.0f} s, held out "
                  f"{diag.split_['validate'][0]:.0f}-{diag.split_['validate'][1]:.0f} s; first "
                  f"{diag.split_['settle']:.0f} s excluded (start-up).",
              "", "## What this sensor set can tell apart", "", *_isolability_lines(diag),
              "", "## Before / after", "", "![overlay](overlay.png)", ""]
    (out / "report.md").write_text("\n".join(lines))

    stamp_report(out / "report.md", stamp())
    return diag.to_json()


def _isolability_lines(diag) -> list:
    """The isolability of the log's sensor set (``diagnosis.json`` ``isolability``) as Markdown lines.

    Parameters
    ----------
    diag : GapDiagnoser
        A fitted diagnoser.
    """
    iso = diag.isolability()
    groups = [g for g in iso["groups"] if len(g) > 1]
    alone = [g[0] for g in iso["groups"] if len(g) == 1]
    lines = [f"Sensors: {', '.join(diag.sensors_)}. From the model's structure (which equation each effect "
             "enters, which measured signals its term depends on), the candidates this sensor set can tell "
             "apart alone: " + (", ".join(f"`{a}`" for a in alone) or "none") + "."]
    if groups:
        lines += ["", "Groups it cannot tell apart by structure (the replay fit decides between them; a verdict "
                  "in one names its group, `verdict.group`):", "",
                  *[f"- {', '.join(f'`{m}`' for m in g)}" for g in groups]]
    v = diag.verdict_
    group = diag.verdict_group(iso)
    group = diag.structural_group(iso)
    if group is not None and len(group) > 1:
        lines += ["", f"The verdict `{v['effect']}` lies in the group {', '.join(f'`{m}`' for m in group)}: "
                  "effects this sensor set cannot tell apart by structure (whether this log tells them apart "
                  "is the verdict's block test above)."]
    return lines


def _distinguish_lines(v) -> list:
    """The verdict's practical distinguishability (schema 4): why it is a group, the block test's pairs
    and what would separate the group."""
    d = v.get("distinguishable")
    if not d:
        return []
    lines = []
    for key in ("group_note", "law_note", "lead_note", "refit_note"):
        if v.get(key):
            lines.append(f"\n{v[key]}.")
    fam = d.get("false_alarm_measured", {})
    lines += ["", f"Can this log tell the leading explanations apart? Held-out block test (Vuong, blocks of "
              f"{d['block_s']:.1f} s, false-alarm rate {100 * d['false_alarm_rate']:g} % stated; "
              f"{fam.get('apart', 0)} of {fam.get('null_pairs', 0)} pairs equal by construction called apart on "
              "this log):", "",
              md_table(["a", "b", "t statistic [-]", "threshold [-]", "blocks", "told apart"],
                       [[f"`{p['a']}`", f"`{p['b']}`", f"{p['statistic']:+.2f}", f"{p['threshold']:.2f}",
                         str(p.get("blocks", "")), "yes" if p["apart"] else "**no**"] for p in d["pairs"]])]
    if v.get("separate_by"):
        lines += ["", "What would tell them apart (the members simulated under each experiment, ranked by how far "
                  "apart it drives their predictions against the noise, Box-Hill):", "",
                  *[f"- {s}" for s in v["separate_by"]]]
    return lines


def fig_confusion(summary):
    """Confusion matrix of the withheld-effect benchmark (rows: withheld effect, columns: verdict).

    Parameters
    ----------
    summary : dict
        The withheld-effect benchmark's summary: ``confusion`` {withheld effect: {verdict: count}},
        ``n_runs``, ``accuracy`` [-].
    """
    plt = _plt()
    cm = summary["confusion"]
    truths = list(cm)
    verdicts = list(next(iter(cm.values())))
    M = np.array([[cm[t][v] for v in verdicts] for t in truths], dtype=float)
    fig, ax = plt.subplots(figsize=(9, 6))
    ax.imshow(M, cmap="Blues")
    for i in range(M.shape[0]):
        for j in range(M.shape[1]):
            if M[i, j]:
                ax.text(j, i, int(M[i, j]), ha="center", va="center", color="k", fontsize=9)
    ax.set_xticks(range(len(verdicts)), verdicts, rotation=40, ha="right", fontsize=8)
    ax.set_yticks(range(len(truths)), truths, fontsize=8)
    ax.set_xlabel("verdict of the diagnosis [-]")
    ax.set_ylabel("withheld effect (dominant) [-]")
    ax.set_title(f"Withheld-effect benchmark: {summary['n_runs']} runs, accuracy {100 * summary['accuracy']:.0f} % "
                 "(diagonal = correct)", fontsize=10)
    fig.tight_layout()
    return fig
