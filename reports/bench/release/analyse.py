#!/usr/bin/env python3
"""Summarises the release probe's rows (probe.patch, PD_REL_PROBE=FILE): per scene, per kind of trial (rejected by
the error control, or passed by it) and per kind of kink inside it (a release only, a stick-slip change only, both),
the true error over tol, the true error over the kinks' bound, the bound over tol, the estimate over tol, and the
trials whose bound is within tol.  Usage: analyse.py NAME=FILE.csv ... > tightness.csv"""
import csv
import sys


def quantile(values, p):
    values = sorted(values)
    return values[min(len(values) - 1, int(p * len(values)))] if values else float("nan")


CATEGORIES = (
    ("release only", lambda r: int(r["releases"]) > 0 and float(r["bslip"]) == 0.0),
    ("stick-slip only", lambda r: int(r["releases"]) == 0),
    ("both", lambda r: int(r["releases"]) > 0 and float(r["bslip"]) > 0.0),
)

out = csv.writer(sys.stdout, lineterminator="\n")
out.writerow(["run", "kind", "kinks", "n", "err_tol_p50", "err_tol_p90", "err_tol_max", "err_over_tol_frac",
              "err_bound_p50", "err_bound_p90", "err_bound_p99", "err_bound_max", "bound_tol_p50", "est_tol_p50",
              "err_est_p50", "allowed", "allowed_err_tol_p50", "allowed_err_tol_max"])
for arg in sys.argv[1:]:
    name, path = arg.split("=", 1)
    rows = list(csv.DictReader(open(path)))
    for kind in ("passed", "rejected"):
        for label, belongs in CATEGORIES:
            sel = [r for r in rows if r["kind"] == kind and belongs(r)]
            if not sel:
                continue
            tol = [float(r["tol"]) for r in sel]
            err = [float(r["e"]) / t for r, t in zip(sel, tol)]
            bound = [float(r["bboth"]) for r in sel]
            ratio = [float(r["e"]) / b for r, b in zip(sel, bound) if b > 0.0]
            est = [float(r["norm"]) / t for r, t in zip(sel, tol)]
            err_est = [e / n for e, n in zip(err, est) if n > 0.0]
            allowed = [e for e, b, t in zip(err, bound, tol) if b <= t]
            out.writerow([name, kind, label, len(sel), "%.3g" % quantile(err, 0.5), "%.3g" % quantile(err, 0.9),
                          "%.3g" % max(err), "%.3f" % (sum(e > 1.0 for e in err) / len(err)),
                          "%.3g" % quantile(ratio, 0.5), "%.3g" % quantile(ratio, 0.9), "%.3g" % quantile(ratio, 0.99),
                          "%.3g" % max(ratio), "%.3g" % quantile([b / t for b, t in zip(bound, tol)], 0.5),
                          "%.3g" % quantile(est, 0.5), "%.3g" % quantile(err_est, 0.5), len(allowed),
                          "%.3g" % quantile(allowed, 0.5), "%.3g" % (max(allowed) if allowed else float("nan"))])
