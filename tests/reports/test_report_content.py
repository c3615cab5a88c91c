#!/usr/bin/env python3
"""What the fixture report shows, checked with parsers independent of the generator's (Python's csv,
json and html.parser): the page is self-contained; the PASS/FAIL matrix has one cell per
(experiment, engine-variant) of results.csv, each showing its error; the numbers in report.json and
report-*.csv equal those in the input CSVs and summaries; the cost to reach 1e-3 follows the
log-log interpolation of the self-convergence error; the horizon of predictability table shows the
horizons of sweep.csv.

usage: test_report_content.py POLYDYN SOURCE_DIR
"""
import csv
import html.parser
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
FIXTURE = os.path.join(SOURCE, "tests", "reports", "fixtures", "gedanken")


def num(text):
    """A CSV number as the schema writes it (%.17g, nan, inf); None when empty."""
    return None if text == "" else float(text)


def from_json(v):
    """A number of report.json: non-finite ones are the strings nan, inf, -inf."""
    return float(v) if isinstance(v, str) else v


def fmt(x):
    """num() of reports/generator/lib/html.mjs for the values of the fixture: 3 significant digits."""
    if 1e-3 <= abs(x) < 1e5:
        t = f"{x:.3g}"
        return t
    m, e = f"{x:.2e}".split("e")
    return f"{m.rstrip('0').rstrip('.')}e{int(e)}"


def same(a, b):
    if a is None or b is None:
        return a is None and b is None
    return (math.isnan(a) and math.isnan(b)) or a == b


def make_report(src, out_dir):
    """polydyn report SRC into OUT_DIR/report.html: (the page's text, report.json)."""
    out = os.path.join(out_dir, "report.html")
    subprocess.run([POLYDYN, "report", src, "-o", out, "--no-viewer"], check=True, stderr=subprocess.DEVNULL,
                   env={**os.environ, "PD_REPORT_GENERATOR": os.path.join(SOURCE, "reports", "generator", "report.mjs")})
    with open(out, encoding="utf-8") as f:
        page = f.read()
    with open(os.path.join(out_dir, "report.json"), encoding="utf-8") as f:
        return page, json.load(f)


class Page(html.parser.HTMLParser):
    """Collects the tags, the matrix cells (with their text) and the scripts of the page."""

    def __init__(self):
        super().__init__()
        self.tags = []
        self.cells = []
        self.cell = None
        self.scripts = []
        self.in_script = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        self.tags.append((tag, a))
        if tag == "td" and "data-experiment" in a:
            self.cell = {**a, "text": ""}
        if tag == "script":
            self.in_script = {"attrs": a, "text": ""}

    def handle_endtag(self, tag):
        if tag == "td" and self.cell is not None:
            self.cells.append(self.cell)
            self.cell = None
        if tag == "script" and self.in_script is not None:
            self.scripts.append(self.in_script)
            self.in_script = None

    def handle_data(self, data):
        if self.cell is not None:
            self.cell["text"] += data
        if self.in_script is not None:
            self.in_script["text"] += data


class ReportInDir(unittest.TestCase):
    """A report written into the temporary directory cls.dir (made by the subclass's setUpClass)."""

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir)

    def table(self, name):
        with open(os.path.join(self.dir, f"report-{name}.csv"), newline="", encoding="utf-8") as f:
            return list(csv.DictReader(f))


class FixtureReport(ReportInDir):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp()
        cls.html, cls.json = make_report(FIXTURE, cls.dir)
        with open(os.path.join(FIXTURE, "results.csv"), newline="", encoding="utf-8") as f:
            cls.results = list(csv.DictReader(f))
        with open(os.path.join(FIXTURE, "sweep.csv"), newline="", encoding="utf-8") as f:
            cls.sweep = [r for r in csv.DictReader(f) if r["scene"] != "scene"]  # two sweeps, header repeated
        cls.page = Page()
        cls.page.feed(cls.html)

    # --- self-contained
    def test_page_loads_nothing_from_outside(self):
        for tag, a in self.page.tags:
            self.assertNotIn("src", a, f"<{tag} src=…>: everything must be inlined")
            if tag == "link":
                self.fail(f"<link {a}>: no external stylesheet or resource")
            for attr in ("href", "action", "poster", "data"):
                self.assertFalse(re.match(r"\s*(https?:)?//", a.get(attr) or ""), f"<{tag} {attr}={a.get(attr)}>")
        self.assertNotRegex(self.html, r"@import|url\(\s*['\"]?(https?:)?//", "no CSS import or url() from outside")
        self.assertNotRegex(self.html, r"<iframe|<embed|<object", "no embedded documents")

    def test_charting_library_and_page_script_are_inlined(self):
        code = [s for s in self.page.scripts if s["attrs"].get("type") != "application/json"]
        self.assertEqual(len(code), 2, "ECharts and the page script, nothing else")
        self.assertIn("Apache ECharts", code[0]["text"][:200])
        self.assertGreater(len(code[0]["text"]), 500_000, "the whole minified library is there")
        charts = json.loads(next(s for s in self.page.scripts if s["attrs"].get("id") == "pd-charts")["text"])
        self.assertEqual(len(charts), len(re.findall(r'<div class="chart" id="chart-\d+"', self.html)))

    def test_charts_include_the_polar_friction_cone_and_log_log_work_precision(self):
        charts = json.loads(next(s for s in self.page.scripts if s["attrs"].get("id") == "pd-charts")["text"])
        polar = [c for c in charts if "polar" in c["option"]]
        self.assertEqual(len(polar), 1)
        self.assertTrue(all(s["coordinateSystem"] == "polar" for s in polar[0]["option"]["series"]))
        loglog = [c for c in charts if c["option"].get("xAxis", {}).get("type") == "log" and c["option"]["yAxis"]["type"] == "log"]
        scenes = list(dict.fromkeys(r["scene"] for r in self.sweep))
        self.assertEqual(len(loglog), 2 * len(scenes), "two diagrams per scene: self-convergence, against the reference")
        # one curve per engine-variant (and setting) of each scene, the self-convergence diagram first
        for k, scene in enumerate(scenes):
            curves = {(r["engine"], r["variant"], r["setting"]) for r in self.sweep if r["scene"] == scene}
            for c in loglog[2 * k:2 * k + 2]:
                self.assertEqual(len(c["option"]["series"]), len(curves))
            self.assertIn("its own finest run", loglog[2 * k]["option"]["yAxis"]["name"])
            self.assertIn("against", loglog[2 * k + 1]["option"]["yAxis"]["name"])
            # the self-convergence diagram draws self_error (no point for an engine's own finest run)
            drawn = sorted(p[1] for s in loglog[2 * k]["option"]["series"] for p in s["data"])
            want = sorted(num(r["self_error"]) for r in self.sweep if r["scene"] == scene and r["self_error"] and num(r["self_error"]) > 0)
            self.assertEqual(drawn, want)

    # --- self-convergence: the title, the horizon of predictability
    def test_self_convergence_title_and_horizon_table(self):
        self.assertIn("Self-convergence (each engine against its own finest run)", self.html)
        self.assertIn("against polydyn soft at tol 1e-12", self.html)
        m = re.search(r'<table class="horizon">(.*?)</table>', self.html, re.S)
        self.assertIsNotNone(m, "the horizon of predictability table")
        rows = re.findall(r"<tr><td>(.*?)</td><td>(.*?)</td>", m.group(1))
        parting = {r["scene"] for r in self.sweep if r["horizon_seconds"]}
        self.assertEqual({scene for scene, _ in rows}, parting, "a row for the scenes whose runs part, only")
        self.assertEqual(len(rows), len({(r["scene"], r["engine"], r["variant"], r["setting"]) for r in self.sweep if r["scene"] in parting}))
        self.assertRegex(self.html, r"No run leaves its own finest run by 0\.1 in cases/gedanken/slide\.scene")
        # every horizon of the csv is in its row's cell, the finest steps (their own reference) are not listed
        text = m.group(1)
        for r in self.sweep:
            if r["horizon_seconds"]:
                self.assertIn(f'{r["setting"]} {fmt(num(r["value"]))}: {fmt(num(r["horizon_seconds"]))} s', text)
        self.assertNotIn("step 2.6e-4", text)

    # --- PASS/FAIL matrix
    def test_matrix_has_one_cell_per_experiment_and_engine_variant(self):
        pairs = {(r["experiment"], f'{r["engine"]} {r["variant"]}') for r in self.results}
        cells = [(c["data-experiment"], c["data-ev"]) for c in self.page.cells]
        self.assertEqual(len(cells), len(set(cells)), "no cell twice")
        self.assertEqual(set(cells), pairs)

    def test_each_matrix_cell_shows_its_status_and_largest_error(self):
        for c in self.page.cells:
            rows = [r for r in self.results if r["experiment"] == c["data-experiment"] and f'{r["engine"]} {r["variant"]}' == c["data-ev"]]
            errors = [num(r["error"]) for r in rows if r["error"] not in ("", "nan")]
            statuses = {r["status"] for r in rows}
            self.assertIn(c["data-status"], statuses)
            if c["data-status"] == "NOT_APPLICABLE":
                # a model prediction on a variant without that model: "n/a", the reason on hover, not judged
                self.assertEqual(statuses, {"NOT_APPLICABLE"})
                self.assertIn("n/a", c["text"])
                self.assertIn("not judged", c["text"])
                self.assertTrue(all(r["note"].startswith("not applicable: " + c["data-reason"]) for r in rows))
                continue
            self.assertIn(c["data-status"], c["text"])
            if statuses == {"PASS"}:
                self.assertEqual(c["data-status"], "PASS")
            if "FAIL" in statuses and "ERROR" not in statuses:
                self.assertEqual(c["data-status"], "FAIL", "a cell with a failing input is not PASS")
            if errors:
                self.assertEqual(float(c["data-error"]), max(errors))
                self.assertRegex(c["text"], r"error [-0-9.e]+( %)?", "the error is shown in the cell")
            else:
                self.assertEqual(c["data-error"], "")

    # --- numbers: report.json and the CSV tables against the inputs
    def test_report_json_results_equal_results_csv(self):
        rows = self.json["results"]
        self.assertEqual(len(rows), len(self.results))
        for csv_row, j in zip(self.results, rows):
            for k in ("experiment", "engine", "variant", "input", "status", "note", "run_dir"):
                self.assertEqual(j[k], csv_row[k], k)
            for k in ("measured", "expected", "error", "tolerance", "wall_seconds"):
                self.assertTrue(same(from_json(j[k]), num(csv_row[k])), f'{csv_row["experiment"]} {k}: {j[k]} vs {csv_row[k]}')

    def test_matrix_numbers_equal_results_csv(self):
        cells = self.json["matrix"]["cells"]
        table = self.table("matrix")
        self.assertEqual(len(table), len(cells))
        for c, t in zip(cells, table):
            rows = [r for r in self.results if r["experiment"] == c["experiment"] and r["engine"] == c["engine"] and r["variant"] == c["variant"]]
            errors = [num(r["error"]) for r in rows if r["error"] not in ("", "nan")]
            self.assertEqual(c["error"], max(errors) if errors else None)
            self.assertEqual(c["passed"], sum(r["status"] == "PASS" for r in rows))
            self.assertEqual(c["inputs"], len(rows))
            walls = [num(r["wall_seconds"]) for r in rows if r["wall_seconds"]]
            self.assertAlmostEqual(c["wall_seconds"] or 0, sum(walls), delta=1e-12)
            self.assertTrue(same(num(t["error"]), c["error"]))
            self.assertEqual(t["status"], c["status"])

    def test_restitution_table_equals_results_csv(self):
        rows = [r for r in self.results if r["quantity"] == "restitution"]
        self.assertTrue(rows)
        table = self.table("restitution")
        self.assertEqual(len(table), len(rows))
        for r in rows:
            t = next(t for t in table if (t["experiment"], t["input"], t["engine"], t["variant"]) == (r["experiment"], r["input"], r["engine"], r["variant"]))
            self.assertEqual(num(t["measured"]), num(r["measured"]))
            self.assertEqual(num(t["predicted"]), num(r["expected"]))
            self.assertEqual(num(t["requested"]), float(r["input"].split("=")[1]))
            g = next(g for g in self.json["restitution"]["rows"] if (g["experiment"], g["input"]) == (r["experiment"], r["input"]))
            self.assertEqual(g["measured"][f'{r["engine"]} {r["variant"]}'], num(r["measured"]))

    def test_friction_cone_equals_results_csv(self):
        rows = [r for r in self.results if r["quantity"] == "stopping_distance" and r["input"].startswith("push_deg=") and r["measured"]]
        self.assertEqual(len(rows), 20)
        traces = {t["ev"]: t for c in self.json["friction-cone"] for t in c["traces"]}
        for r in rows:
            pts = traces[f'{r["engine"]} {r["variant"]}']["points"]
            p = next(p for p in pts if p["push_deg"] == float(r["input"].split("=")[1]))
            self.assertEqual(p["distance"], num(r["measured"]))
        # the isotropy spread of a trace: (max − min) / mean
        d = [num(r["measured"]) for r in rows if r["engine"] == "ode" and r["variant"] == "native"]
        self.assertAlmostEqual(traces["ode native"]["spread"], (max(d) - min(d)) / (sum(d) / len(d)), places=14)

    def test_work_precision_points_equal_sweep_csv(self):
        points = {(s["scene"], c["engine"], c["variant"], c["setting"], p["value"]): p
                  for s in self.json["work-precision"] for c in s["curves"] for p in c["points"]}
        self.assertEqual(len(points), len(self.sweep))
        for r in self.sweep:
            p = points[(r["scene"], r["engine"], r["variant"], r["setting"], num(r["value"]))]
            self.assertTrue(same(p["error"], num(r["error"])))
            self.assertEqual(p["wall_per_sim_second"], num(r["wall_per_sim_second"]))
            self.assertEqual(p["wall_seconds"], num(r["wall_seconds"]))
            self.assertTrue(same(p["self_error"], num(r["self_error"])))
            self.assertEqual(p["self_reference"], r["self_reference"])
            self.assertTrue(same(p["horizon_seconds"], num(r["horizon_seconds"])))

    def test_cost_to_reach_1e_3_is_the_log_log_interpolation_on_the_self_convergence_curve(self):
        target = 1e-3
        cost = {r["ev"]: r for r in self.json["cost"]["rows"]}
        for scene in {r["scene"] for r in self.sweep}:
            for ev in {f'{r["engine"]} {r["variant"]}' for r in self.sweep if r["scene"] == scene}:
                best = None
                for setting in ("tol", "step"):
                    pts = sorted(([num(r["value"]), num(r["self_error"]), num(r["wall_per_sim_second"])] for r in self.sweep
                                  if r["scene"] == scene and f'{r["engine"]} {r["variant"]}' == ev and r["setting"] == setting
                                  and r["self_error"] not in ("", "nan")), reverse=True)
                    for k, (_, e, w) in enumerate(pts):
                        if e <= target:
                            if k == 0:
                                c = w
                            else:
                                e0, w0 = pts[k - 1][1], pts[k - 1][2]
                                s = (math.log(target) - math.log(e0)) / (math.log(e) - math.log(e0))
                                c = math.exp(math.log(w0) + s * (math.log(w) - math.log(w0)))
                            best = c if best is None else min(best, c)
                            break
                got = cost[ev]["to_target"][scene]
                if best is None:
                    self.assertEqual(got["kind"], "never", f"{scene} {ev}")
                else:
                    self.assertAlmostEqual(got["wall_per_sim_second"], best, delta=1e-12 * best, msg=f"{scene} {ev}")
        # ODE converges to its own answer, not to the reference's (0.004 + 2 h): cost read on self_error, not on error
        self.assertEqual(cost["ode native"]["to_target"]["cases/gedanken/slide.scene"]["kind"], "interpolated")
        ode = next(c for s in self.json["work-precision"] if s["scene"] == "cases/gedanken/slide.scene" for c in s["curves"] if c["ev"] == "ode native")
        self.assertEqual(ode["to_target_reference"]["kind"], "never")
        self.assertTrue(all(self.json["cost"]["self_convergence"].values()))
        self.assertIn("to self-convergence error 0.001", self.html)

    def test_cost_table_wall_times_equal_results_csv(self):
        for r in self.json["cost"]["rows"]:
            walls = {}
            for x in self.results:
                if f'{x["engine"]} {x["variant"]}' == r["ev"] and x["wall_seconds"]:
                    walls[x["experiment"]] = walls.get(x["experiment"], 0) + num(x["wall_seconds"])
            if not walls:
                continue
            self.assertAlmostEqual(r["total_wall_seconds"], sum(walls.values()), delta=1e-12)
            w = sorted(walls.values())
            mid = len(w) // 2
            self.assertAlmostEqual(r["median_wall_seconds_per_experiment"], w[mid] if len(w) % 2 else (w[mid - 1] + w[mid]) / 2, delta=1e-12)

    def test_parameters_list_every_engine_setting_of_every_run(self):
        params = {p["ev"]: p for p in self.json["parameters"]}
        runs = {(r["run_dir"], f'{r["engine"]} {r["variant"]}') for r in self.results if r["run_dir"]}
        for run_dir, ev in runs:
            with open(os.path.join(FIXTURE, run_dir, "summary.json"), encoding="utf-8") as f:
                s = json.load(f)
            # values are kept as JSON text (strings as they are)
            settings = {x["key"]: [v["value"] if v["value"] and v["value"][0] not in '-0123456789[{tfn' else json.loads(v["value"])
                                   for v in x["values"]] for x in params[ev]["settings"]}
            source = s.get("engine_settings") or s["settings"]
            for k, v in source.items():
                self.assertIn(v, settings[k], f"{run_dir}: {k}")
            for b in s.get("bodies", []):
                used = b["material"]["used"]
                self.assertTrue(any(m["used"]["kn"] == used["kn"] and m["used"]["cn"] == used["cn"] for m in params[ev]["materials"]))
            # every pair's constants as the run wrote them, listed with the run and the pair's bodies
            for c in s.get("contact_pairs", []):
                used = {k: v for k, v in c.items() if k != "bodies"}
                row = [x for x in params[ev]["pairs"] if x["used"] == used]
                self.assertEqual(len(row), 1, f"{run_dir}: {c['bodies']}")
                self.assertTrue(any(b.endswith(": " + " / ".join(c["bodies"])) for b in row[0]["bodies"]))
        self.assertEqual(len(self.table("parameters")), sum(len(x["values"]) for p in self.json["parameters"] for x in p["settings"])
                         + sum(len(p["materials"]) + len(p["pairs"]) + len(p["adjustments"]) for p in self.json["parameters"]))


class CompareReport(unittest.TestCase):
    def test_comparison_metrics_equal_metrics_csv(self):
        fixture = os.path.join(SOURCE, "tests", "reports", "fixtures", "compare")
        with tempfile.TemporaryDirectory() as d:
            subprocess.run([POLYDYN, "report", fixture, "-o", os.path.join(d, "r.html"), "--no-viewer"], check=True, stderr=subprocess.DEVNULL)
            with open(os.path.join(d, "r.json"), encoding="utf-8") as f:
                rows = json.load(f)["compare"]
            with open(os.path.join(d, "r.html"), encoding="utf-8") as f:
                page = f.read()
        with open(os.path.join(fixture, "metrics.csv"), newline="", encoding="utf-8") as f:
            want = list(csv.DictReader(f))
        self.assertEqual(len(rows), len(want))
        for j, r in zip(rows, want):
            for k, v in r.items():
                if k in ("scene", "engine", "variant", "reference", "restitution_impacts"):
                    self.assertEqual(j[k], v)
                else:
                    self.assertTrue(same(from_json(j[k]), num(v)), f"{k}: {j[k]} vs {v}")
            self.assertIn(r["restitution_impacts"], page)


class PrecisionReport(ReportInDir):
    """Work-precision against the closed form (precision.csv of polydyn gedanken --precision) and the summary that
    opens the report: numbers recomputed here from the CSVs; an engine missing from the build is reported."""

    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp()
        cls.src = os.path.join(cls.dir, "gedanken")
        subprocess.run([POLYDYN, "gedanken", "--only", "a1_restitution,c2_momentum,c3_eccentric_bar", "--precision",
                        "--repeats", "2", "--out", cls.src], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        # as a build without ODE writes it: two not_built rows per experiment instead of ODE's points
        path = os.path.join(cls.src, "precision.csv")
        with open(path, newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            header, rows = reader.fieldnames, list(reader)
        kept, seen = [], set()
        for r in rows:
            if r["engine"] != "ode":
                kept.append(r)
            elif (r["experiment"], r["variant"]) not in seen:
                seen.add((r["experiment"], r["variant"]))
                kept.append({**r, "setting": "", "value": "", "measured": "", "error": "", "status": "not_built", "wall_seconds": "",
                             "wall_per_sim_second": "", "steps": "0", "note": "this build of polydyn has no ode adapter"})
        with open(path, "w", newline="", encoding="utf-8") as f:
            w = csv.DictWriter(f, header, lineterminator="\n")
            w.writeheader()
            w.writerows(kept)
        cls.rows = kept
        with open(os.path.join(cls.src, "results.csv"), newline="", encoding="utf-8") as f:
            cls.results = list(csv.DictReader(f))
        cls.html, cls.json = make_report(cls.src, cls.dir)

    def expected_cost(self, experiment, ev, setting=None, column="wall_per_sim_second"):
        """(kind, cost, smallest error) of one curve (one knob of an engine-variant; None: the cheapest that reaches
        the tolerance): the first setting, loosest first (largest tol or step, fewest iterations), whose error is
        within the tolerance and the next finer setting's too (a run with no answer is outside it), the cost
        (`column`) interpolated log-log from the setting before it unless that one gave no answer or its error falls
        faster than cost^-8 (then at most the cost of the setting that reaches it)."""
        if setting is None:
            curves = [self.expected_cost(experiment, ev, k, column) for k in {r["setting"] for r in self.rows
                      if r["experiment"] == experiment and f'{r["engine"]} {r["variant"]}' == ev}]
            reached = [c for c in curves if c[0] in ("at_most", "interpolated")]
            return min(reached, key=lambda c: c[1]) if reached else curves[0]
        pts = [r for r in self.rows if r["experiment"] == experiment and f'{r["engine"]} {r["variant"]}' == ev
               and (r["setting"] == setting or r["status"] == "not_built")]
        if all(r["status"] == "not_built" for r in pts):
            return "not_built", None, None
        answered = sorted(([float(r["value"]), float(r["error"]), float(r[column])] if r["status"] == "ok"
                           else [float(r["value"]), math.inf, None] for r in pts if r["status"] != "refused"),
                          reverse=setting != "iterations")
        tol = float(pts[0]["tolerance"])
        ok = [p for p in answered if p[1] < math.inf]
        smallest = min(e for _, e, _ in ok) if ok else None
        for k, (_, e, w) in enumerate(answered):
            if e <= tol and (k + 1 == len(answered) or answered[k + 1][1] <= tol):
                if k == 0 or e <= 0 or answered[k - 1][1] == math.inf:
                    return "at_most", w, smallest
                e0, w0 = answered[k - 1][1], answered[k - 1][2]
                if w == w0 or not 0 <= math.log(e0 / e) / math.log(w / w0) <= 8:
                    return "at_most", w, smallest
                s = (math.log(tol) - math.log(e0)) / (math.log(e) - math.log(e0))
                return "interpolated", math.exp(math.log(w0) + s * (math.log(w) - math.log(w0))), smallest
        return "never", None, smallest

    def test_the_cost_against_the_rigid_engines_opens_the_report_then_the_summary(self):
        self.assertEqual(self.json["sections"][:2], ["against", "summary"])
        self.assertIn("precision", self.json["sections"])

    def test_the_first_screen_says_a_cost_is_the_least_of_its_timings(self):
        # precision.csv's cost columns are the least of 2 timings, their spread beside them (docs/validation.md)
        timing = self.json["against"]["timing"]
        self.assertEqual((timing["kind"], timing["repeats"]), ("least_of_timings", 2))
        spreads = sorted(float(r["cpu_max_over_min"]) for r in self.rows if r["status"] == "ok")
        n = len(spreads)
        self.assertAlmostEqual(timing["median_cpu_max_over_min"], (spreads[(n - 1) // 2] + spreads[n // 2]) / 2, delta=1e-12)
        self.assertIn("the least of its 2 timings", html.unescape(self.html))

    def test_cost_ratios_are_the_cpu_costs_to_the_tolerance_over_each_other(self):
        judged = {(r["experiment"], f'{r["engine"]} {r["variant"]}') for r in self.rows if r["judged"] == "true"}
        checked = 0
        for row in self.table("against"):
            if row["experiment"].startswith("median"):
                continue
            self.assertEqual(row["unit"], "cpu")
            mine = self.expected_cost(row["experiment"], "soft implicit", column="cpu_per_sim_second")
            for ev in ("ode native", "ode matched", "bullet native", "bullet matched"):
                key = "ratio_" + ev.replace(" ", "_")
                if key not in row:
                    continue
                other = self.expected_cost(row["experiment"], ev, column="cpu_per_sim_second")
                reached = (row["experiment"], ev) in judged and mine[0] in ("at_most", "interpolated") and \
                    other[0] in ("at_most", "interpolated")
                if not reached:
                    self.assertEqual(row[key], "", f'{row["experiment"]} {ev}')
                    continue
                want = mine[1] / other[1]
                self.assertAlmostEqual(float(row[key]), want, delta=1e-9 * want, msg=f'{row["experiment"]} {ev}')
                checked += 1
        if any(r["engine"] == "bullet" and r["status"] == "ok" for r in self.rows):  # a build with Bullet
            self.assertGreater(checked, 0)

    def test_what_set_polydyns_steps_is_read_from_the_point_it_reaches_at(self):
        limits = ("error", "largest", "stability", "travel", "event", "landing")
        checked = 0
        for row in self.table("against"):
            if row["experiment"].startswith("median") or row["soft_to_tolerance"] != "at_most":
                continue
            point = [r for r in self.rows if r["experiment"] == row["experiment"] and r["engine"] == "soft"
                     and r["variant"] == "implicit" and float(r["value"]) == float(row["soft_setting_value"])]
            self.assertEqual(len(point), 1, row["experiment"])
            self.assertEqual(row["soft_derivatives"], point[0]["derivatives"], row["experiment"])
            for limit in limits:
                self.assertEqual(row["soft_steps_" + limit], point[0]["steps_" + limit], f'{row["experiment"]} {limit}')
            self.assertEqual(sum(int(row["soft_steps_" + l]) for l in limits), int(row["soft_steps"]), row["experiment"])
            checked += 1
        self.assertGreater(checked, 0)

    def test_one_curve_per_experiment_and_engine_variant_with_the_cost_to_its_tolerance(self):
        got = {(r["experiment"], f'{r["engine"]} {r["variant"]}', r["setting"]): r for r in self.table("precision")}
        want = {(r["experiment"], f'{r["engine"]} {r["variant"]}', r["setting"]) for r in self.rows}
        self.assertEqual(set(got), want)
        if any(r["engine"] == "bullet" for r in self.rows if r["status"] != "not_built"):  # a build with Bullet
            self.assertIn(("a1_restitution", "bullet native", "iterations"), want)
        for (experiment, ev, setting), r in got.items():
            kind, cost, smallest = self.expected_cost(experiment, ev, setting)
            self.assertEqual(r["to_tolerance"], kind, f"{experiment} {ev}")
            if cost is not None:
                self.assertAlmostEqual(float(r["wall_per_sim_second"]), cost, delta=1e-12 * cost, msg=f"{experiment} {ev}")
            if smallest is not None:
                self.assertEqual(float(r["smallest_error"]), smallest)
            if kind == "never":
                self.assertIn(r["never_reason"], ("stalls", "still_falling", "no_result", "one_point"))

    def test_a_missing_engine_is_reported_not_built_not_left_out(self):
        rows = [r for r in self.table("precision") if r["engine"] == "ode"]
        self.assertEqual(len(rows), 2 * 3)
        self.assertTrue(all(r["to_tolerance"] == "not_built" for r in rows))
        self.assertIn("not built", self.html)
        summary = {f'{r["engine"]} {r["variant"]}': r for r in self.table("summary")}
        self.assertIn("ode native", summary)

    def test_summary_counts_equal_the_results_and_the_precision_curves(self):
        summary = {f'{r["engine"]} {r["variant"]}': r for r in self.table("summary")}
        for ev in {f'{r["engine"]} {r["variant"]}' for r in self.results if r["status"] not in ("NOT_BUILT",)}:
            cells = {}
            for r in self.results:
                if f'{r["engine"]} {r["variant"]}' == ev:
                    cells.setdefault(r["experiment"], []).append(r["status"])
            judged = [x for x, st in cells.items() if "NOT_APPLICABLE" not in st]
            self.assertEqual(int(summary[ev]["experiments"]), len(judged), ev)
            self.assertEqual(int(summary[ev]["pass"]), sum(all(s == "PASS" for s in cells[x]) for x in judged), ev)
        for ev, r in summary.items():
            if ev.startswith("ode"):
                continue
            judged = {x["experiment"] for x in self.rows if f'{x["engine"]} {x["variant"]}' == ev and x["judged"] == "true"}
            reached = [x for x in judged if self.expected_cost(x, ev)[0] in ("at_most", "interpolated")]
            self.assertEqual((int(r["judged"]), int(r["reached"])), (len(judged), len(reached)), ev)
            costs = sorted(self.expected_cost(x, ev)[1] for x in reached)
            if costs:
                m = len(costs) // 2
                med = costs[m] if len(costs) % 2 else (costs[m - 1] + costs[m]) / 2
                self.assertAlmostEqual(float(r["median_cost_to_tolerance"]), med, delta=1e-12 * med, msg=ev)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
