#!/bin/sh
# The session's benchmark queue (issue 27): MADS from Table 6 starts 2-5, then the pattern search from starts 1-5,
# cost f1, one worker; every finished run is appended to bench/results/identify_benchmark.jsonl (resumable).
# This stop ran its first command only (stopped after MADS 2 to give the core to the MRAC and switch runs; MADS 3 and 4
# and 5 then ran one start at a time with --only-start K); the pattern search ran from Table 6 start 1 only (--only-start 1).
cd "$(dirname "$0")/../.." || exit 1
PY=/work/main/.venv/bin/python
export PYTHONPATH=$PWD
$PY -u bench/bench_identify.py --optimizers mads --cost f1 --starts table6 --only-start 2 3 4 5 --workers 1 \
    --results bench/results/identify_benchmark.jsonl
$PY -u bench/bench_identify.py --optimizers pattern --cost f1 --starts table6 --workers 1 \
    --results bench/results/identify_benchmark.jsonl
