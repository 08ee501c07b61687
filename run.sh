#!/bin/bash
cd /work/runs/ablations
export PYTHONPATH=/work/runs/code_snap7 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
/usr/bin/time -f "ablations wall %e s" /work/main/.venv/bin/python -m pipelines.ablations --params params.yaml \
  --designs 300 --epochs 3 --eval-designs 150 --out out
