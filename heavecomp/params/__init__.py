"""Parameter sets: validated frozen dataclasses with units and bounds; TOML in/out.

>>> from heavecomp.params import paper_a, load
>>> p = paper_a("rotating_eq7")
>>> round(p.k_eff)          # paper A eq. 14 [N/m]
43068
"""

from heavecomp.params.cmc import (CMCParams, dumps, from_dict, load, loads, save, G, P_ATM,
                                  FRICTION_MODELS, HEAVE_KINDS)
from heavecomp.params.sets import SETS, paper_a

__all__ = ["CMCParams", "dumps", "from_dict", "load", "loads", "save", "paper_a", "SETS", "G", "P_ATM",
           "FRICTION_MODELS", "HEAVE_KINDS"]
