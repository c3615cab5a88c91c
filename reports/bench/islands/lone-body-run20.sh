#!/bin/sh
# run20.sh POLYDYN SCENE OUT [ARGS...]: 20 runs of one scene
P=$1; S=$2; O=$3; shift 3
i=0; while [ $i -lt 20 ]; do "$P" run "$S" --out "$O" "$@" >/dev/null || exit 1; i=$((i+1)); done
