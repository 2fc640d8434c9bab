"""The VTK files of `beamrail run --vtk` read back by VTK's own reader (Debian python3-vtk9,
vtkXMLPolyDataReader) and compared with the tables: body positions, displacements and mode shapes
to 1e-12, frame times equal to the t column, a beam drawn as the Euler-Bernoulli cubic of its end
deflection and rotation (a tip-loaded cantilever's curve is its closed-form deflection line), the
design drawn for sweeps and optimizations, and the command line's refusals (exit status 2)."""

import csv
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import support  # noqa: E402

support.require("vtk", "numpy")

import numpy as np  # noqa: E402
import vtk  # noqa: E402
from vtk.util.numpy_support import vtk_to_numpy  # noqa: E402

import unittest  # noqa: E402

TOL = 1e-12


class Read:
    """One .vtp read by vtkXMLPolyDataReader; fails on any error the reader reports."""

    def __init__(self, path):
        errors = []
        reader = vtk.vtkXMLPolyDataReader()
        reader.AddObserver("ErrorEvent", lambda obj, ev: errors.append(ev))
        reader.GetExecutive().AddObserver("ErrorEvent", lambda obj, ev: errors.append(ev))
        reader.SetFileName(path)
        reader.Update()
        if errors or not reader.GetOutput():
            raise AssertionError(f"VTK cannot read {path}: {errors}")
        self.data = reader.GetOutput()
        self.points = vtk_to_numpy(self.data.GetPoints().GetData()) if self.data.GetPoints() \
            else np.zeros((0, 3))

    def point(self, name):
        return vtk_to_numpy(self.data.GetPointData().GetArray(name))

    def cell(self, name):
        a = self.data.GetCellData().GetAbstractArray(name)
        if isinstance(a, vtk.vtkStringArray):
            return [a.GetValue(i) for i in range(a.GetNumberOfValues())]
        return vtk_to_numpy(a)

    def field(self, name):
        return vtk_to_numpy(self.data.GetFieldData().GetArray(name))[0]

    def lines(self):
        out, ids = [], vtk.vtkIdList()
        cells = self.data.GetLines()
        cells.InitTraversal()
        while cells.GetNextCell(ids):
            out.append([ids.GetId(k) for k in range(ids.GetNumberOfIds())])
        return out


def collection(pvd):
    """(times as written, {time: {part: path}}) of a .pvd."""
    folder = os.path.dirname(pvd)
    frames, order = {}, []
    for d in ET.parse(pvd).getroot().find("Collection"):
        t = d.get("timestep")
        if t not in frames:
            frames[t] = {}
            order.append(t)
        frames[t][d.get("name")] = os.path.join(folder, d.get("file"))
    return order, frames


def table(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def load(path):
    with open(path) as f:
        return json.load(f)


def by_body(frame):
    names = frame.cell("body")
    return {n: frame.points[k] for k, n in enumerate(names)}


class VtkFiles(support.TempDir):
    def run_study(self, name, document=None, extra=()):
        path = (support.write_study(self.dir, name, document) if document is not None
                else os.path.join(support.STUDIES, name + ".json"))
        out = os.path.join(self.dir, name)
        support.run(["run", path, "-o", out, "--quiet", *extra])
        return out

    def test_transient_frames_are_the_time_series_rows(self):
        doc = support.study("frame_3d")
        out = self.run_study("frame_3d", doc, ["--vtk"])
        rows = table(os.path.join(out, "timeseries.csv"))
        with open(os.path.join(out, "timeseries.csv")) as f:
            header = f.readline().strip().split(",")
        bodies = [h[:-2] for h in header if h.endswith(".x")]
        times, frames = collection(os.path.join(out, "vtk", "transient.pvd"))
        self.assertEqual(len(times), len(rows))
        self.assertGreater(len(rows), 10)
        checked = 0
        for t, row in zip(times, rows):
            self.assertEqual(float(t), float(row["t"]))  # the same number, as written
            self.assertEqual(set(frames[t]), {"bodies", "glyphs", "elements"})
            f = Read(frames[t]["bodies"])
            self.assertEqual(f.field("TimeValue"), float(row["t"]))
            centres = by_body(f)
            for b in bodies:
                for c, x in zip("xyz", centres[b]):
                    self.assertLessEqual(abs(x - float(row[f"{b}.{c}"])), TOL)
                    checked += 1
        self.assertEqual(checked, 3 * len(bodies) * len(rows))
        # The displacement is measured from the scene's initial configuration.
        last = Read(frames[times[-1]]["bodies"])
        first = Read(frames[times[0]]["bodies"])
        np.testing.assert_allclose(last.point("displacement"), last.points - first.points,
                                   rtol=0, atol=TOL)
        contents = load(os.path.join(out, "vtk", "contents.json"))
        self.assertEqual([a["name"] for a in contents["analyses"]],
                         ["static", "modal", "transient"])
        self.assertEqual(contents["analyses"][2]["frames"], len(rows))

    def test_a_refined_transient_draws_the_run_it_reports(self):
        # A rotor whirling on an axle 0.1 m off its centre, bdf at rtol 1e-7: its verification
        # finds it 21 times its tolerance off, so it is run again at rtol 1e-8 ("refine"), whose
        # frames replace the first run's: one series, as many frames as the time series' rows,
        # each the refined run's.
        doc = {"name": "whirl",
               "scene": {"gravity": [0, 0, 0],
                         "bodies": [{"name": "rotor", "mass": 2, "inertia": [0.01, 0.01, 0.02],
                                     "position": [0.1, 0, 0], "velocity": [0, 0.5, 0],
                                     "angular_velocity": [0, 0, 5]}],
                         "joints": [{"name": "axle", "type": "revolute", "body1": "ground",
                                     "body2": "rotor", "point": [0, 0, 0], "axis": [0, 0, 1]}]},
               "analyses": [{"type": "transient", "name": "spin", "t_end": 2.0,
                             "output_step": 0.02,
                             "integrator": {"method": "bdf", "rtol": 1e-7, "atol": 1e-11}}]}
        out = self.run_study("whirl", doc, ["--vtk"])
        analysis = load(os.path.join(out, "summary.json"))["analyses"][0]
        self.assertIn("refinement", analysis)
        self.assertEqual(analysis["refinement"]["rtol"], 1e-8)
        rows = table(os.path.join(out, "spin.timeseries.csv"))
        times, frames = collection(os.path.join(out, "vtk", "spin.pvd"))
        self.assertEqual(len(times), len(rows))
        for t, row in zip(times, rows):
            self.assertEqual(float(t), float(row["t"]))
            centre = by_body(Read(frames[t]["bodies"]))["rotor"]
            for c, x in zip("xyz", centre):
                self.assertLessEqual(abs(x - float(row[f"rotor.{c}"])), TOL)
        contents = load(os.path.join(out, "vtk", "contents.json"))
        self.assertEqual([(a["name"], a["frames"]) for a in contents["analyses"]],
                         [("spin", len(rows))])
        self.assertEqual(len(os.listdir(os.path.join(out, "vtk", "spin"))), 3 * len(rows))

    def test_static_frames_are_the_undeformed_and_deformed_states(self):
        out = self.run_study("portal_frame", None, ["--vtk"])
        times, frames = collection(os.path.join(out, "vtk", "static.pvd"))
        self.assertEqual([float(t) for t in times], [0.0, 1.0])
        before, after = Read(frames[times[0]]["bodies"]), Read(frames[times[1]]["bodies"])
        names = before.cell("body")
        moved = {r["body"]: r for r in table(os.path.join(out, "static_displacements.csv"))}
        self.assertEqual(set(moved), set(n for n, g in zip(names, before.cell("fixed")) if not g))
        for k, n in enumerate(names):
            if n not in moved:
                continue
            d = [float(moved[n][c]) for c in ("dx", "dy", "dz")]
            for c in range(3):
                self.assertLessEqual(abs(after.points[k][c] - before.points[k][c] - d[c]), TOL)
                self.assertLessEqual(abs(after.point("displacement")[k][c] - d[c]), TOL)
                self.assertEqual(before.point("displacement")[k][c], 0.0)
        # Element forces: those of element_forces.csv, on the deformed frame; none undeformed.
        forces = table(os.path.join(out, "element_forces.csv"))
        e = Read(frames[times[1]]["elements"])
        names = e.cell("element")
        for r in forces:
            k = names.index(r["element"])
            f = e.cell(f"force_end{r['end']}")[k]
            m = e.cell(f"moment_end{r['end']}")[k]
            self.assertEqual(list(f) + list(m),
                             [float(r[c]) for c in ("fx", "fy", "fz", "mx", "my", "mz")])
        self.assertEqual(float(np.abs(Read(frames[times[0]]["elements"]).cell(
            "axial_force")).max()), 0.0)

    def test_mode_shapes_are_the_tables_shapes(self):
        out = self.run_study("portal_frame", None, ["--vtk"])
        times, frames = collection(os.path.join(out, "vtk", "modal.pvd"))
        modes = [r for r in table(os.path.join(out, "modes.csv")) if r["kind"] != "rigid"]
        shapes = table(os.path.join(out, "mode_shapes.csv"))
        self.assertEqual(len(times), 16 * len(modes))
        for m, mode in enumerate(modes):
            first = Read(frames[times[16 * m]]["bodies"])
            self.assertEqual(float(times[16 * m]), m)  # mode k's cycle starts at time k - 1
            self.assertEqual(first.field("mode"), m + 1)
            self.assertEqual(first.field("frequency_hz"), float(mode["frequency_hz"]))
            names = first.cell("body")
            shape = first.point("shape")
            n = 0
            for r in shapes:
                if int(r["mode"]) != m + 1:
                    continue
                k = names.index(r["body"])
                for c, col in enumerate(("dx", "dy", "dz")):
                    self.assertLessEqual(abs(shape[k][c] - float(r[col])), TOL)
                n += 1
            self.assertGreater(n, 0)
            # A quarter cycle on, the bodies have moved by the amplitude along the shape (the
            # rotations are applied exactly, the centres move linearly).
            quarter = Read(frames[times[16 * m + 4]]["bodies"])
            a = quarter.field("amplitude")
            self.assertGreater(a, 0)
            np.testing.assert_allclose(quarter.points - first.points, a * shape, rtol=0,
                                       atol=1e-12 * max(1.0, float(np.abs(a * shape).max())))

    def test_buckling_shapes_are_the_tables_shapes(self):
        out = self.run_study("column_load_cases", None, ["--vtk"])
        times, frames = collection(os.path.join(out, "vtk", "roof.pvd"))
        factors = table(os.path.join(out, "roof.buckling.csv"))
        shapes = table(os.path.join(out, "roof.buckling_shapes.csv"))
        self.assertEqual(len(times), 16 * len(factors))
        f = Read(frames[times[0]]["bodies"])
        self.assertEqual(f.field("factor"), float(factors[0]["factor"]))
        names = f.cell("body")
        for r in shapes:
            if r["mode"] != "1":
                continue
            k = names.index(r["body"])
            for c, col in enumerate(("dx", "dy", "dz")):
                self.assertLessEqual(abs(f.point("shape")[k][c] - float(r[col])), TOL)

    def test_a_tip_loaded_cantilever_is_drawn_as_its_deflection_line(self):
        # A single massless beam: its curve is the Hermite cubic of the tip deflection and
        # rotation, P x^2 (3 L - x) / (6 E I) for a tip load, through both attachment points.
        doc = support.study("bending_tip_load")
        del doc["scene"]["materials"]["steel"]["density"]  # massless: the tip keeps its box
        out = self.run_study("bending_tip_load", doc, ["--vtk"])
        times, frames = collection(os.path.join(out, "vtk", "static.pvd"))
        e = Read(frames[times[1]]["elements"])
        line = e.lines()
        self.assertEqual(len(line), 1)
        pts = e.points[line[0]]
        self.assertEqual(len(pts), 17)
        ei = 2.1e11 * 0.01 ** 4 / 12
        tip = 1.0 / (3 * ei)
        for x, y, z in pts:
            exact = -x * x * (3 - x) / (6 * ei)
            self.assertLessEqual(abs(y - exact), 1e-9 * tip, (x, y, exact))
            self.assertLessEqual(abs(z), 1e-15)
        np.testing.assert_allclose(pts[0], [0, 0, 0], atol=1e-15)
        d = table(os.path.join(out, "static_displacements.csv"))[0]
        np.testing.assert_allclose(pts[-1], [1 + float(d["dx"]), float(d["dy"]), float(d["dz"])],
                                   rtol=0, atol=1e-12)
        self.assertAlmostEqual(pts[-1][1], -tip, delta=1e-6 * tip)
        # The glyph: the uniform box of the tip's mass and inertia (1 kg, 1e-4 kg m^2: edges of
        # sqrt(6e-4) m) and a line from its centre to the beam's end.
        g = Read(frames[times[0]]["glyphs"])
        corners = g.points[:8]
        np.testing.assert_allclose(corners.max(axis=0) - corners.min(axis=0),
                                   [math.sqrt(6e-4)] * 3, rtol=1e-12)

    def test_rails_are_drawn_through_the_carriage_to_the_ends_of_their_travel(self):
        doc = support.study("carriage_two_rails")
        doc["analyses"] = [{"type": "static"}]
        doc.setdefault("outputs", {})["vtk"] = True  # "outputs" does what --vtk does
        doc["responses"] = {k: v for k, v in doc.get("responses", {}).items()
                            if v.get("quantity") in ("displacement", "rotation", "element_force",
                                                     "mass")}
        out = self.run_study("carriage_two_rails", doc)
        times, frames = collection(os.path.join(out, "vtk", "static.pvd"))
        e = Read(frames[times[1]]["elements"])
        rails = [k for k, r in enumerate(e.cell("rail")) if r == 1]
        self.assertEqual(len(rails), len(doc["scene"].get("rails", [])))
        lines = e.lines()
        for k in rails:
            pts = e.points[lines[k]]
            self.assertTrue(np.isfinite(pts).all())
            self.assertGreaterEqual(len(pts), 17)

    def test_joints_are_drawn_with_their_forces_and_gaps(self):
        # A weight W = m g hanging 0.5 m below a spherical joint to ground, and a second one on a
        # bracket 0.5 m beside a fixed joint, both joints at the origin; no elements: each joint
        # gives way by c d = 5e-7 m (docs/model.md "Joints": the stiffness is the weight over
        # the joints' largest lever d, over c). The joint's line runs from its point on ground to its point
        # on the weight; its forces are element_forces.csv's, its gap joint_gaps.csv's.
        m, g, d = 3.0, 9.81, 0.5
        doc = {"name": "joints",
               "scene": {"gravity": [0, -g, 0],
                         "bodies": [{"name": "bob", "mass": m, "inertia": [0.01, 0.02, 0.03],
                                     "position": [0, -d, 0]},
                                    {"name": "bracket", "mass": m, "inertia": [0.01, 0.02, 0.03],
                                     "position": [d, 0, 0]}],
                         "joints": [{"name": "ball", "type": "spherical", "body1": "ground",
                                     "body2": "bob", "point": [0, 0, 0]},
                                    {"name": "weld", "type": "fixed", "body1": "ground",
                                     "body2": "bracket", "point": [0, 0, 0]}]},
               "analyses": [{"type": "static"}]}
        out = self.run_study("joints", doc, ["--vtk"])
        times, frames = collection(os.path.join(out, "vtk", "static.pvd"))
        e = Read(frames[times[1]]["elements"])
        names = e.cell("element")
        self.assertEqual(names, ["ball", "weld"])
        self.assertEqual(list(e.cell("joint")), [1, 1])
        self.assertEqual(list(e.cell("rail")), [0, 0])
        forces = table(os.path.join(out, "element_forces.csv"))
        gaps = {r["joint"]: r for r in table(os.path.join(out, "joint_gaps.csv"))}
        lines = e.lines()
        w = m * g
        for k, name in enumerate(names):
            for r in (r for r in forces if r["element"] == name):
                f = e.cell(f"force_end{r['end']}")[k]
                mo = e.cell(f"moment_end{r['end']}")[k]
                self.assertEqual(list(f) + list(mo),
                                 [float(r[c]) for c in ("fx", "fy", "fz", "mx", "my", "mz")])
            # The joint holds the weight: -W along y at end 2, +W at end 1 (forces on the joint).
            self.assertAlmostEqual(e.cell("force_end2")[k][1], -w, delta=1e-9 * w)
            self.assertAlmostEqual(e.cell("force_end1")[k][1], w, delta=1e-9 * w)
            self.assertEqual(e.cell("gap")[k], float(gaps[name]["gap"]))
            self.assertAlmostEqual(e.cell("gap")[k] / (1e-6 * d), 1.0, delta=1e-5)
            self.assertTrue(math.isnan(e.cell("axial_force")[k]))
            self.assertTrue(math.isnan(e.cell("stress")[k]))
            pts = e.points[lines[k]]
            self.assertEqual(len(pts), 2)
            self.assertAlmostEqual(float(np.linalg.norm(pts[1] - pts[0])), e.cell("gap")[k],
                                   delta=1e-15)
        # The bracket's moment W d about z, on the joint: -W d at end 2.
        self.assertAlmostEqual(e.cell("moment_end2")[1][2], -w * d, delta=1e-9 * w * d)
        # The undeformed frame: the joints closed, no force.
        before = Read(frames[times[0]]["elements"])
        self.assertEqual(list(before.cell("gap")), [0.0, 0.0])
        self.assertEqual(float(np.abs(before.cell("force_end2")).max()), 0.0)

    def test_the_best_design_is_drawn_as_best_scene_json_runs(self):
        out = self.run_study("column_design", None, ["--vtk"])
        contents = load(os.path.join(out, "vtk", "contents.json"))
        self.assertEqual(contents["design"]["which"], "best")
        best = load(os.path.join(out, "best.json"))
        self.assertEqual(contents["design"]["variables"], best["variables"])
        again = os.path.join(self.dir, "again")
        support.run(["run", os.path.join(out, "best_scene.json"), "-o", again, "--vtk",
                     "--quiet"])
        for a in contents["analyses"]:
            t1, f1 = collection(os.path.join(out, "vtk", a["pvd"]))
            t2, f2 = collection(os.path.join(again, "vtk", a["pvd"]))
            self.assertEqual(t1, t2)
            for part in ("bodies", "glyphs", "elements"):
                np.testing.assert_array_equal(Read(f1[t1[-1]][part]).points,
                                              Read(f2[t2[-1]][part]).points)

    def test_a_sweep_draws_the_row_chosen(self):
        doc = support.study("tube_cantilever_sweep")
        path = support.write_study(self.dir, "sweep", doc)
        out = os.path.join(self.dir, "sweep")
        _, err = support.run(["run", path, "-o", out, "--vtk", "--quiet"], expect=2)
        self.assertIn("--design INDEX (0..44", err)
        support.run(["run", path, "-o", out, "--vtk", "--design", "45", "--quiet"], expect=2)
        support.run(["run", path, "-o", out, "--design", "3", "--quiet"], expect=2)
        self.assertFalse(os.path.exists(os.path.join(out, "samples.csv")))  # refused up front
        support.run(["run", path, "-o", out, "--vtk", "--design", "7", "--quiet"])
        row = table(os.path.join(out, "samples.csv"))[7]
        contents = load(os.path.join(out, "vtk", "contents.json"))
        self.assertEqual(contents["design"]["index"], 7)
        self.assertEqual(contents["design"]["variables"],
                         {"outer_diameter": float(row["outer_diameter"]),
                          "wall": float(row["wall"])})
        times, frames = collection(os.path.join(out, "vtk", "static.pvd"))
        before, after = by_body(Read(frames[times[0]]["bodies"])), by_body(
            Read(frames[times[1]]["bodies"]))
        self.assertLessEqual(abs(before["tip"][1] - after["tip"][1] - float(row["deflection"])),
                             TOL)
        # Another row of the same table, without running the sweep again.
        support.run(["run", path, "-o", out, "--vtk", "--design", "30", "--resume", "--quiet"])
        contents = load(os.path.join(out, "vtk", "contents.json"))
        self.assertEqual(contents["design"]["index"], 30)

    def test_bad_choices_of_the_design_are_refused(self):
        for args, words in (
                (["--vtk", "--design", "x"], "EVALUATION"),
                (["--vtk", "--design", "0"], "evaluation 1.."),
                (["--vtk", "--design", "2:1"], "start 1..1"),
                (["--design", "1"], "give --vtk too")):
            _, err = support.run(["run", os.path.join(support.STUDIES, "min_mass_rod.json"), "-o",
                                  os.path.join(self.dir, "o"), "--quiet", *args], expect=2)
            self.assertIn(words, err)
        _, err = support.run(["run", os.path.join(support.STUDIES, "bending_tip_load.json"),
                              "-o", os.path.join(self.dir, "o"), "--vtk", "--design", "1"],
                             expect=2)
        self.assertIn("no design study", err)
        doc = support.study("bending_tip_load")
        doc["outputs"] = {"vtk": "yes"}
        _, err = support.run(["check", support.write_study(self.dir, "bad", doc)], expect=2)
        self.assertIn("/outputs/vtk", err)
        doc["outputs"] = {"vkt": True}
        _, err = support.run(["check", support.write_study(self.dir, "bad", doc)], expect=2)
        self.assertIn('unknown key "vkt" (did you mean "vtk"?)', err)

    def test_an_optimization_row_beyond_its_history_is_refused_after_the_run(self):
        out = os.path.join(self.dir, "rod")
        _, err = support.run(["run", os.path.join(support.STUDIES, "min_mass_rod.json"), "-o", out,
                              "--vtk", "--design", "199", "--quiet"], expect=2)
        self.assertIn("has no such row", err)
        stdout, _ = support.run(["run", os.path.join(support.STUDIES, "min_mass_rod.json"), "-o",
                                 out, "--vtk", "--design", "1:2", "--resume", "--quiet"])
        contents = load(os.path.join(out, "vtk", "contents.json"))
        self.assertEqual((contents["design"]["start"], contents["design"]["evaluation"]), (1, 2))


if __name__ == "__main__":
    unittest.main(verbosity=2)
