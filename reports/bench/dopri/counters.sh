#!/bin/sh
# Step counters of --stepper dopri against step doubling (adaptive), and of implicit-dopri against the default
# (implicit), on the scenes of
# reports/bench/dopri/README.md: deterministic, so one run each. Usage: reports/bench/dopri/counters.sh POLYDYN > counters.csv
set -eu
POLYDYN=${1:-build-release/cli/polydyn}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
echo "scene,tend,stepper,accepted,rejected,derivatives,per_step,steps_error,steps_stability,steps_travel,steps_event,steps_other,onsets_located,onsets_corrected,implicit_steps,wall_seconds"
for entry in cases/hard/stack_10.scene: cases/bench/pile_300.scene:0.3 cases/bench/pile_10.scene: cases/bench/pile_100.scene:0.5 \
  cases/sweep/bounce.scene: cases/sweep/eccentric_impact.scene: cases/sweep/incline_slide.scene: cases/sweep/pile_10.scene: \
  cases/sweep/slide_to_rest.scene: cases/sweep/tumbling_cube.scene: cases/user/domino_row.scene: cases/user/floor_slide.scene: \
  cases/user/ramp_slide.scene: cases/user/ramp_stick.scene: cases/user/vertex_drop.scene: cases/hard/brick_bond.scene:; do
  scene=${entry%%:*}
  tend=${entry#*:}
  for stepper in dopri adaptive implicit implicit-dopri; do
    if [ -n "$tend" ]; then "$POLYDYN" run "$scene" --stepper $stepper --tend "$tend" --out "$OUT/r" >/dev/null
    else "$POLYDYN" run "$scene" --stepper $stepper --out "$OUT/r" >/dev/null; fi
    python3 - "$OUT/r/summary.json" "$scene" "${tend:-scene}" "$stepper" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
c, l, e = d["counts"], d["steps_limited_by"], d.get("events", {})
other = l["largest"] + l["landing"]
print(",".join(str(x) for x in [sys.argv[2], sys.argv[3], sys.argv[4], c["accepted_steps"], c["rejected_steps"],
      c["derivative_evaluations"], "%.2f" % (c["derivative_evaluations"] / c["accepted_steps"]), l["error"],
      l["stability"], l["travel"], l["event"], other, e.get("onsets_located", ""), e.get("onsets_corrected", ""),
      c["implicit_steps"], "%.3f" % d["timing"]["wall_seconds"]]))
PY
  done
done
