#!/bin/sh
# Diagnostic after the shipped replicas: MRAC-2 with its adaptation off (the fixed-gain controller at its ideal
# parameters), one run at 20.44 deg/s: does the 2 omega swing still grow in the taut phase?
while kill -0 $(cat /tmp/tow5_shipped.pid) 2>/dev/null; do sleep 10; done
PYTHONPATH=$PWD nice -n 10 /work/main/.venv/bin/python bench/bench_mrac_replicas.py --plant full-net --rate 20.44 \
  --laws mrac2 --replicas 1 --label fixedgain --set 'mrac.gamma_z=[0,0]' mrac.gamma_r=0 'mrac.gamma_theta=[0,0]' \
  --results bench/results/mrac_replicas.jsonl
