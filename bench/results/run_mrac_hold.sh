#!/bin/sh
# The slack-hold candidate (issue 27), replica 0 of every cell first, then 1, then 2 (resumable).
for n in 1 2 3; do
  PYTHONPATH=$PWD nice -n 10 /work/main/.venv/bin/python bench/bench_mrac_replicas.py --plant full-net --rate 20.44 10.71 \
    --laws mrac2 mrac1 --replicas $n --label hold1 --set mrac.slack_elongation=0.001 mrac.slack_hold_periods=1 \
    --results bench/results/mrac_replicas.jsonl
done
