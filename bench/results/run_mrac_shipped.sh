#!/bin/sh
# The shipped laws (no notch, no hold, the paper's saturation) with replicas on the full net (issue 27): replica 0 of
# every cell first, then 1, then 2 (resumable).
for n in 1 2 3; do
  for rate in 20.44 10.71; do
    PYTHONPATH=$PWD nice -n 10 /work/main/.venv/bin/python bench/bench_mrac_replicas.py --plant full-net --rate $rate \
      --laws mrac2 mrac1 --replicas $n --label shipped --results bench/results/mrac_replicas.jsonl
  done
done
