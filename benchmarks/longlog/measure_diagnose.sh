#!/bin/bash
# Peak RSS and wall time of `heavecomp diagnose` on the two long logs (issue 23.1 goal: each <= 2 GB).
#   PYTHONPATH=$PWD bash benchmarks/longlog/measure_diagnose.sh /tmp/longlog
# Logs and nominal.toml from benchmarks/longlog/make_logs.py.  Each run capped at 8 GB of address space
# (ulimit -v) so that a regression cannot take a shared machine down; results in DIR/measure/*.time.
dir=${1:-/tmp/longlog}
mkdir -p "$dir/measure"
for log in log_24h_10hz.csv.gz log_3h_50hz.csv.gz log_24h_10hz.parquet log_3h_50hz.parquet; do
  ( ulimit -v 8000000
    /usr/bin/time -v python -m heavecomp diagnose "$dir/$log" --params "$dir/nominal.toml" \
      --out "$dir/measure/out_$log" --jobs 2 --quiet ) > "$dir/measure/$log.out" 2> "$dir/measure/$log.time"
  echo "$log exit=$? $(grep -E 'Maximum resident' "$dir/measure/$log.time" | awk '{print $6/1e3 " MB peak RSS"}'),"\
       "$(grep Elapsed "$dir/measure/$log.time" | awk '{print $8 " wall"}'), load $(cut -d' ' -f1-3 /proc/loadavg)"
done
