#!/bin/bash
# Reruns every committed failure of campaigns 40-64 (list.txt: generator, seed, scene) in the soak as found, soft engine
# with islands on and off, two at a time, and writes the rows of their summaries to summary.csv here.
# usage: reports/reliability/rerun-40-64/rerun.sh POLYDYN SCRATCH_DIR
set -eu
POLYDYN=$1 SCRATCH=$2
HERE=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$SCRATCH"
export POLYDYN SCRATCH
xargs -P2 -L1 sh -c '"$POLYDYN" soak --generator "$0" --seed "$1" --first "$2" --scenes 1 --budget 60 \
  --engines soft,soft-islands-off --out "$SCRATCH/c$1-$2" >/dev/null 2>&1 || true' <"$HERE/list.txt"
{
  echo "seed,scene,kind,engine,status,steps,penetration_over_delta_max"
  for d in "$SCRATCH"/c*-*; do tail -n +2 "$d/summary.csv" | awk -F, '{print $1","$2","$3","$6","$7","$10","$11}'; done |
    sort -t, -k1,1n -k2,2n -k4,4
} >"$HERE/summary.csv"
