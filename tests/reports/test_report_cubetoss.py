#!/usr/bin/env python3
"""The cube-toss section of `polydyn report`, on what `polydyn cubetoss` writes for a small
synthetic toss file (make_tosses.py): the headline numbers equal summary.csv's, the typical toss is the
one nearest the median, its errors recomputed from the run directories equal the command's own at
the end of the toss, the section sits among the Gedanken sections when a report directory has
cubetoss/, the replay payload holds the record and every engine's run, and malformed cube-toss files
are refused with FILE:LINE and exit 2 before anything is written. Python's csv and json only: no code
shared with the generator.

usage: test_report_cubetoss.py POLYDYN SOURCE_DIR
"""
import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

POLYDYN, SOURCE = sys.argv[1], sys.argv[2]
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from replay_files import read_replay, same_trajectory  # noqa: E402
GEDANKEN = os.path.join(HERE, "fixtures", "gedanken")
FAKE_VIEWER = os.path.join(HERE, "fixtures", "fake-viewer.js")
ENV = {**os.environ, "PD_REPORT_GENERATOR": os.path.join(SOURCE, "reports", "generator", "report.mjs")}
# The section recomputes the errors from trajectory.csv (17 digits); per_toss.csv prints the command's
# own with 9 significant digits (≤ 5e-9 relative rounding), hence 1e-8 relative, plus an absolute floor
# for errors near zero.
RECOMPUTE_REL, RECOMPUTE_ABS = 1e-8, 1e-12


def rows(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def report(directory, *args):
    return subprocess.run([POLYDYN, "report", directory, *args], env=ENV, capture_output=True, text=True)


def close(a, b):
    return abs(a - b) <= RECOMPUTE_ABS + RECOMPUTE_REL * abs(b)


class CubetossReport(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp()
        data = os.path.join(cls.tmp, "tosses.csv")
        subprocess.run([sys.executable, os.path.join(HERE, "make_tosses.py"), data, "7"], check=True)
        cls.ct = os.path.join(cls.tmp, "ct")
        subprocess.run([POLYDYN, "cubetoss", "--data", data, "--out", cls.ct, "--tosses", "all"], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        cls.fit = os.path.join(cls.tmp, "fit")
        subprocess.run([POLYDYN, "cubetoss", "fit", "--data", data, "--out", cls.fit, "--max-evals", "4", "--engines", "soft,ode"],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        r = report(cls.ct, "--viewer", FAKE_VIEWER)
        assert r.returncode == 0, r.stderr
        with open(os.path.join(cls.ct, "report.json"), encoding="utf-8") as f:
            cls.json = json.load(f)
        with open(os.path.join(cls.ct, "report.html"), encoding="utf-8") as f:
            cls.html = f.read()
        cls.summary = rows(os.path.join(cls.ct, "summary.csv"))
        cls.per_toss = rows(os.path.join(cls.ct, "per_toss.csv"))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp)

    def test_a_cubetoss_directory_alone_gives_the_cubetoss_section(self):
        self.assertEqual(self.json["sections"], ["cubetoss"])
        self.assertIn('<section id="cubetoss">', self.html)

    def test_headline_numbers_equal_summary_csv_on_the_test_tosses(self):
        head = self.json["cubetoss"]["headline"]
        self.assertEqual(self.json["cubetoss"]["split"], "test")
        want = [r for r in self.summary if r["split"] == "test"]
        self.assertEqual(len(head), len({(r["engine"], r["variant"], r["params"]) for r in want}))
        for r in want:
            h = next(x for x in head if (x["engine"], x["variant"], x["params"]) == (r["engine"], r["variant"], r["params"]))
            q = r["quantity"]
            for stat in ("mean", "median", "p90"):
                self.assertEqual(h[q][stat], float(r[stat]), f"{r['engine']} {q} {stat}")
            self.assertEqual((h["completed"], h["tosses"]), (int(r["completed"]), int(r["tosses"])))
        table = rows(os.path.join(self.ct, "report-cubetoss.csv"))
        for t in table:
            r = next(x for x in want if (x["engine"], x["params"], x["quantity"]) == (t["engine"], t["params"], "pos_err_end"))
            self.assertEqual(float(t["pos_err_end_median"]), float(r["median"]))
            self.assertEqual(float(t["pos_err_end_p90"]), float(r["p90"]))

    def test_typical_toss_is_the_soft_test_toss_nearest_the_median(self):
        soft = [r for r in self.per_toss if r["engine"] == "soft" and r["split"] == "test" and r["status"] == "ok"]
        errs = sorted(float(r["pos_err_end"]) for r in soft)
        n = len(errs)
        median = errs[n // 2] if n % 2 else (errs[n // 2 - 1] + errs[n // 2]) / 2
        best = min(soft, key=lambda r: (abs(float(r["pos_err_end"]) - median), int(r["toss"])))
        typ = self.json["cubetoss"]["typical"]
        self.assertEqual(typ["toss"], int(best["toss"]))
        self.assertEqual(typ["median"], median)

    def test_typical_errors_recomputed_from_the_runs_equal_the_commands_at_the_end(self):
        typ = self.json["cubetoss"]["typical"]
        engines = [r for r in self.per_toss if int(r["toss"]) == typ["toss"] and r["status"] == "ok"]
        self.assertEqual(len(typ["runs"]), len(engines))
        for run in typ["runs"]:
            row = next(r for r in engines if f'{r["engine"]} {r["variant"]}' == run["label"])
            self.assertTrue(close(run["pos_err_end"], float(row["pos_err_end"])), f'{run["label"]}: {run["pos_err_end"]} vs {row["pos_err_end"]}')
            self.assertTrue(close(run["rot_err_end_rad"], float(row["rot_err_end_rad"])), run["label"])
            self.assertEqual(run["samples"], int(row["samples"]))
        over = rows(os.path.join(self.ct, "report-cubetoss-typical.csv"))
        self.assertEqual(len(over), sum(r["samples"] for r in typ["runs"]))
        self.assertTrue(all(float(r["pos_err"]) >= 0 and 0 <= float(r["rot_err_rad"]) <= math.pi for r in over))

    def test_replay_payload_is_the_record_then_every_engines_run(self):
        blocks = re.findall(r'<details class="replay" data-run="[^"]*" data-replay="([^"]*)">', self.html)
        self.assertEqual(len(blocks), 1)
        payload = read_replay(os.path.join(self.ct, "report-replays"), blocks[0])
        typ = self.json["cubetoss"]["typical"]
        self.assertEqual([r["run"] for r in payload["runs"]],
                         [f'runs/{typ["toss"]}/record'] + [r["run_dir"] for r in typ["runs"]])
        with open(os.path.join(self.ct, f'runs/{typ["toss"]}/record/trajectory.csv'), encoding="utf-8") as f:
            self.assertTrue(same_trajectory(payload["runs"][0]["trajectory"], f.read()))

    def test_without_a_viewer_no_replay_but_the_charts_of_the_typical_toss(self):
        with tempfile.TemporaryDirectory() as d:
            r = report(self.ct, "-o", os.path.join(d, "r.html"), "--no-viewer")
            self.assertEqual(r.returncode, 0, r.stderr)
            with open(os.path.join(d, "r.html"), encoding="utf-8") as f:
                page = f.read()
        self.assertNotIn('<details class="replay"', page)
        charts = json.loads(re.search(r'<script type="application/json" id="pd-charts">(.*?)</script>', page, re.S).group(1))
        # two distributions (position, rotation) and three over time (height, position, rotation error)
        self.assertEqual(len(charts), 5)

    def test_fit_results_give_the_fitted_table_and_a_typical_toss_without_motion(self):
        r = report(self.fit, "--no-viewer")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(self.fit, "report.json"), encoding="utf-8") as f:
            j = json.load(f)["cubetoss"]
        fit = rows(os.path.join(self.fit, "fit.csv"))
        self.assertEqual([(f["engine"], f["mu"]) for f in j["fit"]], [(f["engine"], float(f["mu"])) for f in fit])
        self.assertEqual(j["typical"]["params"], "fitted")
        self.assertEqual(j["typical"]["runs"], [], "fit keeps no run directories")
        with open(os.path.join(self.fit, "report.html"), encoding="utf-8") as f:
            self.assertIn("No run directories of this toss", f.read())

    def test_beside_the_gedanken_results_the_section_comes_before_the_experiments(self):
        with tempfile.TemporaryDirectory() as d:
            both = os.path.join(d, "g")
            shutil.copytree(GEDANKEN, both)
            shutil.copytree(self.ct, os.path.join(both, "cubetoss"))
            r = report(both, "--no-viewer")
            self.assertEqual(r.returncode, 0, r.stderr)
            with open(os.path.join(both, "report.json"), encoding="utf-8") as f:
                j = json.load(f)
        s = j["sections"]
        self.assertIn("cubetoss", s)
        self.assertLess(s.index("cubetoss"), s.index("experiments"))
        self.assertIn("matrix", s)
        self.assertEqual(j["cubetoss"]["directory"], "cubetoss")
        self.assertEqual(j["cubetoss"]["typical"]["runs"][0]["run_dir"].split("/")[0], "cubetoss")

    # --- malformed input: FILE:LINE, exit 2, nothing written
    def refused(self, edit, pattern):
        with tempfile.TemporaryDirectory() as d:
            bad = os.path.join(d, "bad")
            shutil.copytree(self.ct, bad, ignore=shutil.ignore_patterns("report*"))
            edit(bad)
            r = report(bad, "--no-viewer")
            self.assertEqual(r.returncode, 2, r.stderr)
            self.assertRegex(r.stderr, pattern)
            self.assertEqual([n for n in os.listdir(bad) if n.startswith("report")], [], "nothing written")

    @staticmethod
    def replace_line(path, number, old, new):
        with open(path, encoding="utf-8") as f:
            lines = f.read().split("\n")
        lines[number - 1] = lines[number - 1].replace(old, new, 1)
        with open(path, "w", encoding="utf-8") as f:
            f.write("\n".join(lines))

    def test_a_bad_status_in_summary_csv_is_refused_with_its_line(self):
        self.refused(lambda d: self.replace_line(os.path.join(d, "summary.csv"), 3, ",ok,", ",great,"),
                     r"summary\.csv:3: status: expected one of ok, partial, failed, not built, found 'great'")

    def test_a_bad_number_in_per_toss_csv_is_refused_with_its_line(self):
        self.refused(lambda d: self.replace_line(os.path.join(d, "per_toss.csv"), 4, ",ok,", ",ok,x"),
                     r"per_toss\.csv:4: samples: not a number")

    def test_a_cubetoss_directory_without_summary_csv_is_refused(self):
        def move(d):
            os.mkdir(os.path.join(d, "cubetoss"))
            shutil.copy(os.path.join(GEDANKEN, "results.csv"), d)
        self.refused(move, r"cubetoss/summary\.csv: missing")

    def test_a_broken_record_of_the_typical_toss_is_refused_with_its_line(self):
        typ = self.json["cubetoss"]["typical"]["toss"]
        self.refused(lambda d: self.replace_line(os.path.join(d, f"runs/{typ}/record/trajectory.csv"), 5, ",cube,", ",cube,zz"),
                     rf"runs/{typ}/record/trajectory\.csv:5: x: not a number")


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
