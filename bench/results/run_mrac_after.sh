#!/bin/sh
# After the shipped replicas: the candidates' missing single runs (rate0.6 at 10.71 deg/s; notch MRAC-1 at 20.44 deg/s).
while kill -0 $(cat /tmp/tow5_shipped.pid) 2>/dev/null; do sleep 10; done
PYTHONPATH=$PWD nice -n 10 /work/main/.venv/bin/python bench/bench_mrac_replicas.py --plant full-net --rate 10.71 \
  --laws mrac2 mrac1 --replicas 1 --label rate0.6 --set mrac.rate_filter_time=0.595 --results bench/results/mrac_replicas.jsonl
PYTHONPATH=$PWD nice -n 10 /work/main/.venv/bin/python bench/bench_mrac_replicas.py --plant full-net --rate 20.44 \
  --laws mrac1 --replicas 1 --label notch --set mrac.breathing_notch=true --results bench/results/mrac_replicas.jsonl
