"""report.html in a real browser: Debian's headless Chromium (through chromedriver and
python3-selenium) opens the report of one example study from disk: no script errors in its
console, the 3-D view draws (a canvas of many distinct colours) and responds to its controls, every
number the page shows from summary.json equals summary.json, every scalar of summary.json is shown,
the plots load and the tables sort.

    report_browser_test.py transient | static_modal | optimize
"""

import csv
import io
import json
import os
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import support  # noqa: E402

support.require("selenium", "PIL", "matplotlib", programs=("chromium", "chromedriver", "node"))

from PIL import Image  # noqa: E402

# The three example reports: a study of studies/ each, run with --vtk.
EXAMPLES = {
    "transient": "carriage_two_rails",
    "static_modal": "portal_frame",
    "optimize": "column_design",
}
WHICH = sys.argv.pop(1) if len(sys.argv) > 1 and sys.argv[1] in EXAMPLES else "static_modal"


def scalars(value, pointer=""):
    if isinstance(value, dict):
        for k, v in value.items():
            yield from scalars(v, f"{pointer}/{k.replace('~', '~0').replace('/', '~1')}")
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from scalars(v, f"{pointer}/{i}")
    else:
        yield pointer, value


class Report(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        import shutil
        import tempfile
        cls.dir = tempfile.mkdtemp(prefix="beamrail-browser-test-")
        cls.study = EXAMPLES[WHICH]
        cls.out = os.path.join(cls.dir, cls.study)
        support.run(["run", os.path.join(support.STUDIES, cls.study + ".json"), "-o", cls.out,
                     "--vtk", "--quiet"])
        support.report(cls.out)
        cls.summary = support.load(os.path.join(cls.out, "summary.json"))
        cls.driver = support.chromium()
        start = time.time()
        cls.driver.get("file://" + os.path.join(cls.out, "report.html"))
        while time.time() - start < 20:
            state = cls.driver.execute_script(
                "return [document.body.dataset.viewerReady, document.body.dataset.viewerError]")
            if state[0] or state[1]:
                break
            time.sleep(0.05)
        cls.cleanup = lambda: (support.close(cls.driver), shutil.rmtree(cls.dir, True))

    @classmethod
    def tearDownClass(cls):
        cls.cleanup()

    def js(self, script, *args):
        return self.driver.execute_script(script, *args)

    def test_no_script_errors(self):
        errors = [e for e in self.driver.get_log("browser") if e["level"] == "SEVERE"]
        self.assertEqual(errors, [])

    def test_the_3d_view_draws(self):
        self.assertIsNone(self.js("return document.body.dataset.viewerError || null"))
        self.assertEqual(self.js("return document.body.dataset.viewerReady"), "1")
        canvas = self.driver.find_element("id", "beamrail-canvas")
        self.assertGreater(canvas.size["width"], 300)
        image = Image.open(io.BytesIO(canvas.screenshot_as_png)).convert("RGB")
        colours = image.getcolors(maxcolors=1 << 24)
        self.assertGreater(len(colours), 100, "the canvas is (nearly) blank")
        # No one colour (the background) covers all but a sliver of it.
        self.assertLess(max(c for c, _ in colours) / (image.width * image.height), 0.98)
        # The scene's bodies and elements are what was drawn: without them, thousands of pixels
        # change (the grid and axes stay).
        self.js("const v = window.beamrailViewer; v.boxMesh.visible = false;"
                "v.curves.visible = false; v.render();")
        bare = Image.open(io.BytesIO(canvas.screenshot_as_png)).convert("RGB")
        self.js("const v = window.beamrailViewer; v.boxMesh.visible = true;"
                "v.curves.visible = true; v.render();")
        changed = sum(a != b for a, b in zip(image.getdata(), bare.getdata()))
        self.assertGreater(changed, 2000)

    def test_numbers_shown_equal_summary_json(self):
        shown = self.js("return Array.from(document.querySelectorAll('[data-pointer]'))"
                        ".map(e => [e.dataset.pointer, e.textContent])")
        self.assertGreater(len(shown), 20)
        for pointer, text in shown:
            value = support.pointer(self.summary, pointer)
            if isinstance(value, bool):
                self.assertEqual(text, "true" if value else "false", pointer)
            elif isinstance(value, (int, float)):
                self.assertEqual(float(text), value, pointer)  # exactly: the shortest repr
            elif value is None:
                self.assertEqual(text, "null", pointer)
            else:
                self.assertEqual(text, str(value), pointer)
        every = {p for p, _ in scalars(self.summary)}
        self.assertEqual(every - {p for p, _ in shown}, set())

    def test_plots_load(self):
        sizes = self.js("return Array.from(document.images).map(i => [i.alt, i.naturalWidth])")
        self.assertGreaterEqual(len(sizes), 2)
        for alt, width in sizes:
            self.assertGreater(width, 300, alt)

    def test_tables_sort(self):
        tables = self.js("return Array.from(document.querySelectorAll('table.data'))"
                         ".map(t => t.dataset.file || t.id)")
        self.assertTrue(tables)
        # The last numeric column of the first data table with several rows, ascending then
        # descending.
        index = self.js("""
            const t = Array.from(document.querySelectorAll('table.data')).find(t => t.dataset.file && t.tBodies[0].rows.length > 2);
            const heads = Array.from(t.tHead.rows[0].cells);
            let col = -1;
            heads.forEach((h, k) => { if (Array.from(t.tBodies[0].rows).every(r => !isNaN(Number(r.cells[k].textContent)))) col = k; });
            t.id = t.id || 'sorted-table';
            heads[col].click();
            return [t.id, col];""")
        values = self.js("return Array.from(document.getElementById(arguments[0]).tBodies[0].rows)"
                         ".map(r => Number(r.cells[arguments[1]].textContent))", *index)
        self.assertEqual(values, sorted(values))
        self.js("document.getElementById(arguments[0]).tHead.rows[0].cells[arguments[1]]"
                ".click()", *index)
        values = self.js("return Array.from(document.getElementById(arguments[0]).tBodies[0].rows)"
                         ".map(r => Number(r.cells[arguments[1]].textContent))", *index)
        self.assertEqual(values, sorted(values, reverse=True))

    def choose_view(self, kind):
        titles = self.js("return Array.from(document.getElementById('viewer-view').options)"
                         ".map(o => o.textContent)")
        k = next(i for i, t in enumerate(titles) if f"({kind}" in t)
        self.js("const s = document.getElementById('viewer-view'); s.value = String(arguments[0]);"
                "s.dispatchEvent(new Event('change'));", k)
        return titles[k]

    def renders(self):
        return int(self.js("return document.body.dataset.viewerRenders"))

    @unittest.skipUnless(WHICH == "transient", "the transient example")
    def test_a_transient_plays(self):
        self.choose_view("transient")
        before = self.renders()
        self.driver.find_element("id", "viewer-play").click()
        time.sleep(0.8)
        self.driver.find_element("id", "viewer-play").click()
        self.assertGreater(int(self.js("return document.getElementById('viewer-frame').value")), 0)
        self.assertGreater(self.renders(), before + 2)
        label = self.js("return document.getElementById('viewer-label').textContent")
        self.assertRegex(label, r"^t = [0-9.e-]+ s, displacements x [0-9]")

    @unittest.skipUnless(WHICH == "static_modal", "the static and modal example")
    def test_a_mode_swings_and_its_amplitude_slides(self):
        self.choose_view("modal")
        modes = [r for r in support.rows(os.path.join(self.out, "modes.csv"))
                 if r["kind"] != "rigid"]
        self.js("const s = document.getElementById('viewer-mode'); s.value = '1';"
                "s.dispatchEvent(new Event('change'));")
        label = self.js("return document.getElementById('viewer-label').textContent")
        self.assertTrue(label.startswith(f"mode 2: {float(modes[1]['frequency_hz']):.6g} Hz"),
                        label)
        before = self.renders()
        self.js("const s = document.getElementById('viewer-scale'); s.value = '1';"
                "s.dispatchEvent(new Event('input'));")
        self.assertEqual(self.renders(), before + 1)
        amplitude = float(self.js(
            "return document.getElementById('viewer-label').textContent").split("amplitude ")[1])
        contents = support.load(os.path.join(self.out, "vtk", "contents.json"))
        modal = next(a for a in contents["analyses"] if a["type"] == "modal")
        self.assertEqual(amplitude, float(f"{10 * modal['modes'][1]['amplitude']:.3g}"))
        self.choose_view("static")
        label = self.js("return document.getElementById('viewer-label').textContent")
        self.assertTrue(label.startswith("deformed, displacements x "), label)

    @unittest.skipUnless(WHICH == "optimize", "the optimization example")
    def test_the_best_design_is_drawn_and_its_constraints_shown(self):
        titles = self.js("return Array.from(document.getElementById('viewer-view').options)"
                         ".map(o => o.textContent)")
        self.assertTrue(titles and all(t.startswith("best design: ") for t in titles), titles)
        best = support.load(os.path.join(self.out, "best.json"))
        rows = self.js("return Array.from(document.getElementById('best-constraints').tBodies[0]"
                       ".rows).map(r => Array.from(r.cells).map(c => c.textContent))")
        keys = list(best["constraints"][0])
        self.assertEqual(len(rows), len(best["constraints"]))
        for row, c in zip(rows, best["constraints"]):
            for k, text in zip(keys, row):
                v = c[k]
                if isinstance(v, bool):
                    self.assertEqual(text, "true" if v else "false")
                elif isinstance(v, (int, float)):
                    self.assertEqual(float(text), v)
                else:
                    self.assertEqual(text, str(v))


if __name__ == "__main__":
    unittest.main(verbosity=2)
