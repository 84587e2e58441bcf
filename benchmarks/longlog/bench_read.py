"""Reading a long log: heavecomp's streamed reader against plain ``pandas.read_csv`` in one go.

    python benchmarks/longlog/bench_read.py /tmp/longlog/log_24h_10hz.csv.gz [more files...]

One process.  Both readers are imported and warmed up on the file's first lines first; then each
reads the whole file twice, alternating (heavecomp, pandas, heavecomp, pandas).  Per read: wall time
and the peak resident memory *above* the process' resident size just before it (a thread samples
``/proc/self/statm`` every 2 ms; the allocator returns freed memory with ``malloc_trim`` between reads).
The peer is ``pandas.read_csv(path)`` (it decompresses and parses in C, keeps every column as float64;
no checks, no line numbers, no units).  heavecomp: :func:`heavecomp.io.series.read_series` with the
five contract columns (every check of the measured-run contract's reader, line numbers kept).

Writes ``result_read.json`` beside this script.
"""

import ctypes
import gc
import json
import os
import sys
import threading
import time
from pathlib import Path

PAGE = os.sysconf("SC_PAGE_SIZE")


def rss() -> int:
    with open("/proc/self/statm", encoding="ascii") as fh:
        return int(fh.read().split()[1]) * PAGE


class Peak:
    """Peak resident size above the start, sampled on a thread while the block runs."""

    def __enter__(self):
        gc.collect()
        try:
            ctypes.CDLL("libc.so.6").malloc_trim(0)
        except OSError:
            pass
        self.base = rss()
        self.peak = self.base
        self.stop = False

        def watch():
            while not self.stop:
                self.peak = max(self.peak, rss())
                time.sleep(0.002)

        self.thread = threading.Thread(target=watch, daemon=True)
        self.thread.start()
        self.t0 = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.wall = time.perf_counter() - self.t0
        self.peak = max(self.peak, rss())
        self.stop = True
        self.thread.join()
        self.growth = self.peak - self.base


def main(files) -> dict:
    import pandas as pd

    from heavecomp.io.series import read_series

    cols = ("t", "heave", "stroke", "pressure", "wob")
    out = {"load_average": os.getloadavg(), "files": {}}
    for f in files:
        f = Path(f)
        pd.read_csv(f, nrows=100)  # warm-up: imports, the C parser
        res = {"heavecomp": [], "pandas": []}
        for _ in range(2):
            with Peak() as p:
                s = read_series(f, cols)
                n = s["t"].size
            del s
            res["heavecomp"].append({"wall_s": p.wall, "peak_growth_mb": p.growth / 1e6, "rows": n})
            with Peak() as p:
                df = pd.read_csv(f)
                n = len(df)
            del df
            res["pandas"].append({"wall_s": p.wall, "peak_growth_mb": p.growth / 1e6, "rows": n})
        best = {k: {"wall_s": min(r["wall_s"] for r in v), "peak_growth_mb": min(r["peak_growth_mb"] for r in v)}
                for k, v in res.items()}
        res["ratio_time"] = best["heavecomp"]["wall_s"] / best["pandas"]["wall_s"]
        res["ratio_memory"] = best["heavecomp"]["peak_growth_mb"] / best["pandas"]["peak_growth_mb"]
        res["size_mb"] = f.stat().st_size / 1e6
        out["files"][f.name] = res
        print(f"{f.name}: heavecomp {best['heavecomp']['wall_s']:.2f} s, +{best['heavecomp']['peak_growth_mb']:.0f} MB; "
              f"pandas.read_csv {best['pandas']['wall_s']:.2f} s, +{best['pandas']['peak_growth_mb']:.0f} MB; "
              f"time ratio {res['ratio_time']:.2f}, memory ratio {res['ratio_memory']:.2f}", flush=True)
    out["load_average_after"] = os.getloadavg()
    (Path(__file__).parent / "result_read.json").write_text(json.dumps(out, indent=2) + "\n", encoding="utf-8")
    return out


if __name__ == "__main__":
    main(sys.argv[1:] or ["/tmp/longlog/log_24h_10hz.csv.gz", "/tmp/longlog/log_3h_50hz.csv.gz"])
