#!/bin/sh
# The shipped [mrac] (range damping 1000 N s/m, rate estimate 0.595 s; written out as in the 10.71 / 20.44 deg/s rows)
# on the full net at a third spin rate, Table 3's highest (29.01 deg/s): replica 0 of both laws first, then replica 1
# (resumable: a run already in the results file is not repeated).
for n in 1 2; do
  PYTHONPATH=$PWD nice -n 10 /work/main/.venv/bin/python -u bench/bench_mrac_replicas.py --plant full-net --rate 29.01 \
    --laws mrac2 mrac1 --replicas $n --label range1000_rate0.6 --set mrac.range_damping=1000 mrac.rate_filter_time=0.595 \
    --results bench/results/mrac_replicas.jsonl
done
