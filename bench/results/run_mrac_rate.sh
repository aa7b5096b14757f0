#!/bin/sh
# Candidate: the laws' rate estimate with its corner at the reference model's natural frequency (tau = 1/omega_m =
# 0.595 s) instead of a decade above it (issue 27). Replica 0 of every cell first, then 1 (resumable).
for n in 1 2 3; do
  for rate in 20.44 10.71; do
    PYTHONPATH=$PWD nice -n 10 /work/main/.venv/bin/python bench/bench_mrac_replicas.py --plant full-net --rate $rate \
      --laws mrac2 mrac1 --replicas $n --label rate0.6 --set mrac.rate_filter_time=0.595 \
      --results bench/results/mrac_replicas.jsonl
  done
done
