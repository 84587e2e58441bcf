#!/bin/bash
# Peak RSS and wall time of `heavecomp monitor` on the two long logs (issue 23 item 1 goal: each <= 2 GB).
#   PYTHONPATH=$PWD bash benchmarks/longlog/measure_monitor.sh /tmp/longlog
# Logs and nominal.toml from benchmarks/longlog/make_logs.py.  Each run capped at 8 GB of address space
# (ulimit -v) and niced; results in DIR/measure_monitor/*.time.
dir=${1:-/tmp/longlog}
mkdir -p "$dir/measure_monitor"
for log in log_24h_10hz.csv.gz log_3h_50hz.csv.gz; do
  ( ulimit -v 8000000
    nice -n 5 /usr/bin/time -v python -m heavecomp monitor "$dir/$log" --params "$dir/nominal.toml" \
      --out "$dir/measure_monitor/out_$log" --quiet ) > "$dir/measure_monitor/$log.out" 2> "$dir/measure_monitor/$log.time"
  echo "$log exit=$? $(grep -E 'Maximum resident' "$dir/measure_monitor/$log.time" | awk '{print $6/1e3 " MB peak RSS"}'),"\
       "$(grep Elapsed "$dir/measure_monitor/$log.time" | awk '{print $8 " wall"}'), load $(cut -d' ' -f1-3 /proc/loadavg)"
done
