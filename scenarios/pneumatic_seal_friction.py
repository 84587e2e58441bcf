"""Does paper B's friction measurement (zero-phase FIR, twice-differentiated displacement) give a
consistent friction-velocity picture on real data — the TU Delft O-ring seal files at 1-7 bar — and how
does the sliding friction grow with pressure (F_C + C_p p, paper A eq. 4's pressure term)?
"""

from __future__ import annotations

import sys
from pathlib import Path

from heavecomp.analysis import pneumatic_friction as PF
from heavecomp.data import SEAL_FRICTION
from heavecomp.analysis import pneumatic_plots as PLT
from heavecomp.report.figures import save
from heavecomp.report.scenario import md_table, parse_args, write_metrics, write_report

DATA = SEAL_FRICTION


def build(folder=DATA) -> dict:
    summ = PF.seal_summary(folder)
    runs = {r["file"].removesuffix(".csv"): PF.seal_friction(Path(folder) / r["file"]) for r in summ["rows"]}
    return {"summary": summ, "runs": runs}


def main(argv=None) -> int:
    args = parse_args(argv, "pneumatic_seal_friction", __doc__)
    res = build()
    s = res["summary"]
    save(PLT.plot_seal(res["runs"]), args.out / "seal_friction.png", dpi=100)
    write_metrics(args.out, s)
    write_report(args.out, "Seal friction measured from pressure and displacement (TU Delft O-ring data)", [
        __doc__, "![seal](seal_friction.png)",
        md_table(["file", "p [bar]", "friction v>0 [N]", "friction v<0 [N]", "Coulomb (half difference) [N]",
                  "speed [mm/s]"],
                 [(r["file"], r["pressure_Pa"] / 1e5, r["friction_pos_N"], r["friction_neg_N"], r["coulomb_N"],
                   r["speed_m_s"] * 1e3) for r in s["rows"]]),
        f"Fit: F_C = {s['coulomb_at_zero_N']:.2f} N + {s['pressure_coefficient_N_per_Pa'] * 1e5:.2f} N/bar x p. "
        "The data were resampled to 100 Hz (the logger clock has gaps), the position differentiated with a "
        "2 Hz zero-phase FIR; friction = force - p A (authors' definition; the moving mass is unknown, its "
        "inertia is neglected at these steady strokes).",
    ])
    return 0


if __name__ == "__main__":
    sys.exit(main())
