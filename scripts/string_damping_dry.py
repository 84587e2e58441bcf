"""Does ``string_damping`` (c dv |dv / v_r|^(n - 1), n in [0.1, 3]) carry a rate-independent string damping?
(issue 30 item 4: "a string damping whose law's shape is carried, not only its slope").

    python scripts/string_damping_dry.py SEED OUT_DIR [--eps 0.02]

A study, not a truth law of the generator: a dry-friction element in the string, T += F_y tanh(dv / eps)
(dv = dz_h + v - v_b; rate-independent for |dv| >> eps: the large-amplitude limit of a Bouc-Wen element),
planted by the benchmark generator in place of its quadratic drag for this one run (``string_damping``'s
truth law is restored afterwards), sized to 4.5-5.5 x its floor, and diagnosed with every candidate by
``heavecomp diagnose`` as a user runs it.  When this study was written a Bouc-Wen element could not be an
effect (an effect's ``rates`` got the stroke, its speed and the pressure only); a string effect's
``string_rates`` now get the stretch rate, and ``string_hysteresis`` is that element (the hysteretic law
of ``string_damping``).  Seeds 830000-830099 (``heavecomp.benchmark.seeds``).
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from heavecomp.effects.base import Effect  # noqa: E402
from heavecomp.params.core import q  # noqa: E402


class TruthDryString(Effect):
    """A dry-friction element in the string: T += F_y tanh(dv / eps)."""

    name = "string_damping"
    hook = "string"

    @dataclass(frozen=True)
    class Params:
        f_y: float = q(1e4, "N", bounds=(0.0, 1e7), symbol="F_y", doc="dry friction level of the string element")
        eps: float = q(0.02, "m/s", bounds=(1e-4, 1.0), symbol="eps", doc="relative speed of the tanh's smoothing")

    @staticmethod
    def string(dv, T, x, PP, f_y, eps):
        return T + f_y * np.tanh(dv / eps)


def main(argv) -> int:
    from heavecomp.benchmark import Case, generate
    from heavecomp.benchmark import truth as TR
    from heavecomp.benchmark.truth.base import Draw, TruthLaw
    from heavecomp.cli import main as cli
    from heavecomp.params import dumps

    seed, out = int(argv[0]), Path(argv[1])
    eps = float(argv[argv.index("--eps") + 1]) if "--eps" in argv else 0.02

    def draw(rng, setting):
        return Draw({"f_y": rng.uniform(5e3, 2e4), "eps": eps}, "f_y", 2e6)

    saved = TR.LAWS["string_damping"]
    TR.LAWS["string_damping"] = TruthLaw("string_damping", "string_formation", draw, plant=TruthDryString)
    try:
        tr = generate(Case("string_damping", seed, "named", duration=300.0, size=(4.5, 5.5)))
    finally:
        TR.LAWS["string_damping"] = saved
    out.mkdir(parents=True, exist_ok=True)
    log, nom = tr.to_csv(out / "run.csv"), out / "nominal.toml"
    nom.write_text(dumps(tr.nominal))
    rc = cli(["diagnose", str(log), "--params", str(nom), "--out", str(out / "d"), "--jobs", "1", "--quiet"])
    d = json.loads((out / "d" / "diagnosis.json").read_text())
    v = d["verdict"]
    row = {"seed": seed, "truth": tr.truth["parameters"], "gap_to_noise": tr.truth["gap_to_noise"],
           "verdict": {k: v.get(k) for k in ("effect", "confidence", "parameters", "explained", "shrink", "at_bound")},
           "candidates": [{k: c.get(k) for k in ("effect", "explained", "score", "parameters")}
                          for c in d["candidates"][:4]]}
    (out / "study.json").write_text(json.dumps(row, indent=1, default=float))
    print(json.dumps(row, default=float))
    return rc


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
