"""scripts/report's plots: every plot type comes out of a study in studies/ (transient body
coordinates and energy, modal frequencies and shapes, the static deformed shape, buckling factors
and shapes, a sweep's responses and its pairwise view, an optimization's convergence, the
work-precision chart), each axis labelled with its unit, the captions' counts those of the tables;
and the refusals of scripts/report (exit status 2)."""

import html
import json
import os
import re
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import support  # noqa: E402

support.require("matplotlib", "numpy", programs=("node",))

# Study -> the plots its report holds (plots/<stem>.png).
PLOTS = {
    "bending_tip_period": ["transient.motion", "transient.energy"],
    "column_load_cases": ["wind.deformed", "roof.factors", "roof.shapes", "modal.frequencies",
                          "modal.shapes"],
    "tube_cantilever_sweep": ["sweep.responses", "sweep.pairs"],
    "column_design": ["optimize.convergence", "wind.deformed", "roof.shapes"],
    "work_precision_reference": ["work_precision"],
}


class Plots(support.TempDir):
    def make(self, name, vtk=True):
        out = os.path.join(self.dir, name)
        support.run(["run", os.path.join(support.STUDIES, name + ".json"), "-o", out, "--quiet"]
                    + (["--vtk"] if vtk else []))
        support.report(out)
        with open(os.path.join(out, "plots", "index.json")) as f:
            return out, json.load(f)

    def check(self, name, index, out):
        files = [os.path.splitext(os.path.basename(p["file"]))[0] for p in index]
        self.assertEqual(sorted(files), sorted(PLOTS[name]))
        for p in index:
            with open(os.path.join(out, p["file"]), "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
            self.assertTrue(p["axes"], p["file"])
            for labels in p["axes"]:
                for label in labels:
                    self.assertRegex(label, r"\[[^\]]+\]", f"{p['file']}: {label!r} has no unit")
            self.assertIn("caption", p)
        with open(os.path.join(out, "report.html")) as f:
            page = f.read()
        for p in index:
            self.assertTrue(html.escape(p["caption"]) in page, p["caption"])

    def test_single_runs(self):
        for name in ("bending_tip_period", "column_load_cases"):
            out, index = self.make(name)
            self.check(name, index, out)
        # The static deformed shape's caption gives the largest displacement the VTK files hold.
        caption = next(p["caption"] for p in index if "deformed" in p["file"])
        self.assertRegex(caption, r"magnified \d+ times")

    def test_design_studies(self):
        out, index = self.make("tube_cantilever_sweep", vtk=False)
        self.check("tube_cantilever_sweep", index, out)
        rows = support.rows(os.path.join(out, "samples.csv"))
        ok = sum(r["status"] == "ok" and r["warnings"] == "0" for r in rows)
        caption = next(p["caption"] for p in index if p["file"].endswith("responses.png"))
        self.assertIn(f"({ok} ok, ", caption)
        self.assertIn("outer_diameter [m]", [label for p in index for a in p["axes"]
                                             for label in a])
        out, index = self.make("column_design")
        self.check("column_design", index, out)
        out, index = self.make("work_precision_reference", vtk=False)
        self.check("work_precision_reference", index, out)

    def test_a_report_without_vtk_files_says_how_to_get_them(self):
        out, index = self.make("bending_tip_load", vtk=False)
        with open(os.path.join(out, "report.html")) as f:
            self.assertIn("No 3-D view: the results hold no VTK files", f.read())

    def test_bad_input(self):
        _, err = support.report(os.path.join(self.dir, "nothing"), expect=2)
        self.assertIn("is not a folder", err)
        _, err = support.report(self.dir, expect=2)
        self.assertIn("holds no summary.json", err)
        with open(os.path.join(self.dir, "summary.json"), "w") as f:
            f.write("{not json")
        _, err = support.report(self.dir, expect=2)
        self.assertRegex(err, re.escape("summary.json cannot be read"))


class Pieces(unittest.TestCase):
    """The report's own computations on data made for them (an adversarial review, 2026-12-01)."""

    @classmethod
    def setUpClass(cls):
        sys.path.insert(0, os.path.join(support.SOURCE, "scripts", "report_lib"))
        import plots
        import report
        cls.plots, cls.report = plots, report

    def test_a_joint_leaves_the_beams_their_force_colours(self):
        # A joint's axial force is NaN in the VTK files: it turned every element grey (no force)
        # where the page promises red for tension and blue for compression.
        nan = float("nan")
        colours = self.report.force_colours([2468.0, nan, -1234.0, 0.0])
        self.assertEqual(colours[0], [0.84, 0.15, 0.16])  # the largest tension: full red
        self.assertEqual(colours[1], [0.55, 0.55, 0.55])  # the joint: grey
        self.assertEqual(colours[2], [round(0.55 + 0.5 * (c - 0.55), 3)
                                      for c in (0.12, 0.47, 0.71)])  # half the largest
        self.assertEqual(colours[3], [0.55, 0.55, 0.55])

    def test_units_of_a_joint_gap_and_a_segmentation_target(self):
        units = self.report.units_of({
            "responses": {"gap": {"quantity": "joint_gap"}},
            "study": {"variables": [{"name": "band",
                                     "pointer": "/scene/segmentation/max_frequency_hz"}]}})
        self.assertEqual(units, {"gap": "m", "band": "Hz"})

    def test_a_sweep_draws_each_design_at_its_own_value(self):
        # A failed row that has the response is drawn at its value (it was drawn at the smallest
        # value of the panel, another design's); one without it sits on the x axis.
        rows = [{"status": "ok", "warnings": "0", "r": "1.0", "m": "3.2663"},
                {"status": "ok", "warnings": "2", "r": "2.0", "m": "3.4"},
                {"status": "failed", "warnings": "0", "r": "3.0", "m": "3.5919"},
                {"status": "invalid", "warnings": "0", "r": "4.0", "m": "nan"},
                {"status": "timeout", "warnings": "0", "r": "5.0", "m": ""}]
        p = self.plots.sweep_points(rows, "r", "m")
        self.assertEqual(p["ok"], ([1.0], [3.2663]))
        self.assertEqual(p["warned"], ([2.0], [3.4]))
        self.assertEqual(p["failed"], ([3.0], [3.5919]))
        self.assertEqual(p["no_value"], [4.0, 5.0])


if __name__ == "__main__":
    unittest.main(verbosity=2)
