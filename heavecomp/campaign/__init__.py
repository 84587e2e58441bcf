"""Sea-state campaigns: scatter diagram x friction regimes x variants x seeds.

>>> from heavecomp.campaign import load, run_campaign        # doctest: +SKIP
>>> camp = load("heavecomp/campaign/default_campaign.toml")  # doctest: +SKIP
>>> res = run_campaign(camp, "out/", workers=2)              # doctest: +SKIP

numba (batch, stats) and dask load on first use.
"""

from heavecomp.campaign.execute import run_campaign
from heavecomp.campaign.spec import Campaign, Run, default, load, loads

__all__ = ["Campaign", "Run", "load", "loads", "default", "run_campaign", "simulate_batch", "statistics"]


def __getattr__(name):
    if name == "simulate_batch":
        from heavecomp.campaign.batch import simulate_batch
        return simulate_batch
    if name == "statistics":
        from heavecomp.campaign import stats
        return stats.statistics
    raise AttributeError(name)
