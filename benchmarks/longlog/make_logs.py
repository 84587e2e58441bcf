"""Write the two long logs of the benchmark (issue 23 item 1): 24 h at 10 Hz and 3 h at 50 Hz.

A clean log (no change) of the project's own generator (:func:`heavecomp.benchmark.long_logs.long_log`,
JONSWAP sea, paper-A parameters, the generator's measurement noise), written as a gzip CSV (SI units,
``TestRun.to_csv``'s layout) and as Parquet (one float64 column per channel, row groups of 100 000).

    python benchmarks/longlog/make_logs.py /tmp/longlog

writes ``log_24h_10hz.csv.gz``, ``log_24h_10hz.parquet``, ``log_3h_50hz.csv.gz``, ``log_3h_50hz.parquet``
and ``nominal.toml`` (the parameter file to diagnose against) into the folder.
"""

import gzip
import sys
import time
from pathlib import Path

import numpy as np

from heavecomp.benchmark.long_logs import long_log

LOGS = {"log_24h_10hz": (86400.0, 10.0), "log_3h_50hz": (10800.0, 50.0)}


def write(run, stem: Path) -> None:
    cols = ["t", "heave", "stroke", "pressure", "wob"]
    data = np.column_stack([run.t] + [run.columns[c] for c in cols[1:]])
    with gzip.open(f"{stem}.csv.gz", "wt", compresslevel=6) as fh:
        np.savetxt(fh, data, delimiter=",", header=",".join(cols), comments="", fmt="%.10g")
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table({c: data[:, j] for j, c in enumerate(cols)}), f"{stem}.parquet", row_group_size=100_000)


def main(out) -> None:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    nominal = None
    for name, (duration, rate) in LOGS.items():
        t0 = time.perf_counter()
        run = long_log([], seed=1, duration=duration, rate=rate)
        write(run, out / name)
        nominal = run.nominal
        print(f"{name}: {run.t.size} samples, {time.perf_counter() - t0:.1f} s", flush=True)
    from heavecomp.params.cmc import save

    save(nominal, out / "nominal.toml")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "/tmp/longlog")
