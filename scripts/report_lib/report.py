"""scripts/report RESULTS_DIR: the plots of a beamrail results folder (PNG files in
RESULTS_DIR/plots/) and one self-contained report.html (RESULTS_DIR/report.html): the study's
summary, warnings, tables (sortable), the plots, and a 3-D view of the scene drawn from the run's
VTK files (three.js, bundled into the page: it opens offline from disk). Usage in scripts/report."""

import argparse
import base64
import csv
import html
import json
import math
import os
import subprocess
import sys

import numpy as np

import plots
import vtkfiles

# Rows of a CSV table shown in the page; the file holds them all.
MAX_ROWS = 1000
# Frames of a transient in the 3-D view, and the bytes their points may take.
MAX_FRAMES = 400
MAX_VIEW_BYTES = 40e6

RESPONSE_UNITS = {"frequency": "Hz", "buckling_factor": "-", "displacement": "m",
                  "rotation": "rad", "peak_displacement": "m", "mass": "kg", "max_stress": "Pa",
                  "joint_gap": "m", "expression": "-"}


class BadInput(Exception):
    """A results folder the report cannot be made of: exit status 2."""


def read_json(path, what):
    try:
        with open(path) as f:
            return json.load(f)
    except FileNotFoundError:
        raise BadInput(f"{what} {path} does not exist")
    except (OSError, ValueError) as e:
        raise BadInput(f"{what} {path} cannot be read: {e}")


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return (rows[0], rows[1:]) if rows else ([], [])


def read_dicts(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def escape_pointer(key):
    return str(key).replace("~", "~0").replace("/", "~1")


def text_of(value):
    """A JSON scalar as shown: numbers as JSON writes them (the shortest text that reads back)."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def units_of(study):
    """Units of the responses and design variables of a study (resolved_study.json)."""
    units = {}
    for name, r in (study.get("responses") or {}).items():
        q = r.get("quantity", "")
        if q == "element_force":
            units[name] = "N m" if str(r.get("component", "")).startswith("m") else "N"
        else:
            units[name] = RESPONSE_UNITS.get(q, "-")
    loads = (study.get("scene") or {}).get("loads", []) if isinstance(study.get("scene"),
                                                                      dict) else []
    for v in (study.get("study") or {}).get("variables", []):
        pointer = v.get("pointer", "")
        pointer = pointer[0] if isinstance(pointer, list) and pointer else pointer
        units[v.get("name", "")] = pointer_unit(str(pointer), loads)
    return units


def pointer_unit(pointer, loads):
    parts = pointer.strip("/").split("/")
    keys = [p for p in parts if not p.isdigit()]
    last = keys[-1] if keys else ""
    if "gravity" in keys:
        return "m/s^2"
    if "sections" in keys:
        return {"S": "m^2", "Ix": "m^4", "Iy": "m^4", "Iz": "m^4", "Wy": "m^3",
                "Wz": "m^3"}.get(last, "m")
    if "materials" in keys:
        return {"E": "Pa", "G": "Pa", "density": "kg/m^3"}.get(last, "-")
    if "loads" in keys and last == "value":
        try:
            return "N m" if loads[int(parts[2])].get("type") == "torque" else "N"
        except (IndexError, ValueError, AttributeError):
            return "N"
    table = {"mass": "kg", "inertia": "kg m^2", "position": "m", "point": "m", "point1": "m",
             "point2": "m", "point3": "m", "velocity": "m/s", "angular_velocity": "rad/s",
             "damping": "s", "min_length": "m", "travel": "m", "segments": "-", "at": "s",
             "from": "s", "to": "s", "frequency": "Hz", "phase": "rad", "t_end": "s",
             "output_step": "s", "time": "s", "max_frequency_hz": "Hz"}
    return table.get(last, "-")


# ---------------------------------------------------------------------------------------------
# The 3-D view: the VTK files turned into points per frame for viewer.js.

def b64(array, dtype):
    return base64.b64encode(np.ascontiguousarray(array, dtype=dtype).tobytes()).decode()


def view_of(results, entry, prefix):
    coll = vtkfiles.Collection(os.path.join(results, "vtk", entry["pvd"]))
    kind = entry["type"]
    g0, e0 = coll.read(0, "glyphs"), coll.read(0, "elements")
    n_glyph, n_curve = len(g0.points), len(e0.points)
    everything = np.vstack([g0.points, e0.points]) if n_glyph + n_curve else np.zeros((1, 3))
    origin = (everything.min(axis=0) + everything.max(axis=0)) / 2
    # The boxes of the scene's bodies (those of the bodies a split beam generates would hide its
    # curves: ParaView shows them).
    b0 = coll.read(0, "bodies")
    generated = {int(i) for i, g in zip(b0.cell_data["body_index"], b0.cell_data["generated"])
                 if g}
    boxes = []
    polys = g0.cells.get("Polys", [])
    box_body = g0.cell_data["body_index"][len(g0.cells.get("Lines", [])):]
    for b in range(0, len(polys) - 5, 6):
        if int(box_body[b]) in generated:
            continue
        first = int(min(int(q.min()) for q in polys[b:b + 6]))
        boxes.extend(range(first, first + 8))
    levers = [int(i) for line in g0.cells.get("Lines", []) for i in line]
    curves = [[int(c[0]), int(len(c)), int(rail)]
              for c, rail in zip(e0.cells.get("Lines", []), e0.cell_data.get("rail", []))]
    size = float(entry.get("scene_size") or 1.0)
    view = {"name": entry["name"], "type": kind, "size": size, "origin": origin.tolist(),
            "n_glyph_points": n_glyph, "n_curve_points": n_curve, "boxes": b64(boxes, "<i4"),
            "levers": b64(levers, "<i4"), "curves": curves, "default_scale": 1.0}

    def points(k):
        g, e = coll.read(k, "glyphs"), coll.read(k, "elements")
        return np.vstack([g.points, e.points]) - origin, g, e

    if kind in ("modal", "buckling"):
        base, _, _ = points(0)
        view["positions"] = [b64(base, "<f4")]
        view["frames"] = [{"t": 0, "label": "about"}]
        view["modes"] = []
        for m in entry.get("modes", []):
            _, g, e = points(m["first_frame"])
            shape = np.vstack([g.point_data["shape"], e.point_data["shape"]])
            value = m.get("frequency_hz", m.get("factor"))
            label = (f"mode {m['mode']}: {value:.6g} Hz" if kind == "modal"
                     else f"mode {m['mode']}: load factor {value:.6g}")
            view["modes"].append({"label": label, "frame": 0, "shape": b64(shape, "<f4"),
                                  "amplitude": m["amplitude"]})
        view["title"] = f"{prefix}{entry['name']} ({kind}: {len(view['modes'])} modes)"
        return view
    n = len(coll.frames)
    step = max(1, math.ceil(n / MAX_FRAMES),
               math.ceil(n * (n_glyph + n_curve) * 12 / MAX_VIEW_BYTES))
    chosen = list(range(0, n, step))
    if chosen[-1] != n - 1:
        chosen.append(n - 1)
    frames, positions, largest = [], [], 0.0
    first = None
    for k in chosen:
        p, g, e = points(k)
        first = p if first is None else first
        largest = max(largest, float(np.abs(p - first).max()) if len(p) else 0.0)
        positions.append(b64(p, "<f4"))
        t = coll.frames[k][0]
        label = ("undeformed" if k == 0 else "deformed") if kind == "static" else f"t = {t:.6g} s"
        frames.append({"t": t, "label": label})
        if kind == "static" and k == n - 1 and "axial_force" in e.cell_data:
            view["curve_colors"] = force_colours(e.cell_data["axial_force"])
    view["positions"], view["frames"] = positions, frames
    if largest > 0 and largest < 0.02 * size:
        view["default_scale"] = plots.nice_factor(0.05 * size / largest)
    what = "undeformed and deformed" if kind == "static" else f"{len(frames)} of {n} frames"
    view["title"] = f"{prefix}{entry['name']} ({kind}: {what})"
    return view


def force_colours(axial):
    """Red for tension, blue for compression, grey for none, by |N| over the largest. A joint's
    axial force is NaN in the VTK files (it has none): grey, and not part of the largest."""
    magnitudes = np.abs(np.asarray(axial, dtype=float))
    finite = magnitudes[np.isfinite(magnitudes)]
    top = float(finite.max()) if len(finite) else 0.0
    out = []
    for n in axial:
        s = abs(n) / top if top > 0 and math.isfinite(n) else 0.0
        end = (0.84, 0.15, 0.16) if n > 0 else (0.12, 0.47, 0.71)
        out.append([round(0.55 + s * (c - 0.55), 3) for c in end])
    return out


# ---------------------------------------------------------------------------------------------
# The page.

class Page:
    def __init__(self):
        self.parts = []
        self.nav = []

    def section(self, anchor, title):
        self.nav.append((anchor, title))
        self.parts.append(f'<h2 id="{anchor}">{html.escape(title)}</h2>')

    def add(self, text):
        self.parts.append(text)

    def value_table(self, rows, table_id=None, units=None):
        """rows: (label, pointer or None, value)."""
        out = [f'<table class="kv sortable"{f" id={chr(34)}{table_id}{chr(34)}" if table_id else ""}>'
               "<thead><tr><th>name</th><th>value</th>" + ("<th>unit</th>" if units else "") +
               "</tr></thead><tbody>"]
        for label, pointer, value in rows:
            attr = f' data-pointer="{html.escape(pointer)}"' if pointer is not None else ""
            unit = f"<td>{html.escape(units.get(label, ''))}</td>" if units else ""
            out.append(f"<tr><td>{html.escape(str(label))}</td>"
                       f'<td class="v"{attr}>{html.escape(text_of(value))}</td>{unit}</tr>')
        out.append("</tbody></table>")
        self.add("".join(out))

    def csv_table(self, path, title):
        header, rows = read_csv(path)
        name = os.path.basename(path)
        note = (f" (the first {MAX_ROWS} of {len(rows)} rows; the file holds them all)"
                if len(rows) > MAX_ROWS else f" ({len(rows)} rows)")
        self.add(f"<h3>{html.escape(title)}</h3><p class=\"note\">{html.escape(name)}"
                 f"{html.escape(note)}; click a column's title to sort by it</p>")
        out = [f'<div class="scroll"><table class="sortable data" data-file="{html.escape(name)}">'
               "<thead><tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in header) +
               "</tr></thead><tbody>"]
        for row in rows[:MAX_ROWS]:
            out.append("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>")
        out.append("</tbody></table></div>")
        self.add("".join(out))

    def figure(self, path, caption):
        with open(path, "rb") as f:
            data = base64.b64encode(f.read()).decode()
        self.add(f'<figure><img alt="{html.escape(caption)}" src="data:image/png;base64,{data}">'
                 f"<figcaption>{html.escape(caption)}</figcaption></figure>")


def flat(value, pointer):
    """(pointer, scalar) of every scalar under value."""
    if isinstance(value, dict):
        for k, v in value.items():
            yield from flat(v, f"{pointer}/{escape_pointer(k)}")
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from flat(v, f"{pointer}/{i}")
    else:
        yield pointer, value


def summary_sections(page, summary, units):
    """The summary's scalars, its warnings and the responses."""
    scalars = [(k, "/" + escape_pointer(k), v) for k, v in summary.items()
               if not isinstance(v, (dict, list))]
    page.section("summary", "Summary")
    page.value_table(scalars, "summary-table")
    warnings = summary.get("warnings") or []
    page.section("warnings", f"Warnings ({len(warnings)})")
    if warnings:
        page.add("<ul class=\"warnings\">" + "".join(
            f'<li data-pointer="/warnings/{i}">{html.escape(str(w))}</li>'
            for i, w in enumerate(warnings)) + "</ul>")
    else:
        page.add("<p>None.</p>")
    responses = summary.get("responses")
    if isinstance(responses, dict) and responses:
        page.section("responses", "Responses")
        page.value_table([(k, "/responses/" + escape_pointer(k), v) for k, v in responses.items()],
                         "responses-table", units)


def detail_sections(page, summary):
    """The rest of summary.json: each analysis, the model, a batch's starts, scaling, best, ..."""
    page.section("details", "Details")
    for key, value in summary.items():
        if key in ("warnings", "responses") or not isinstance(value, (dict, list)):
            continue
        if key == "analyses" and isinstance(value, list):
            for i, a in enumerate(value):
                title = f"analysis {a.get('name', i)} ({a.get('type', '')}): {a.get('status', '')}"
                page.add(f'<div class="card"><h3>{html.escape(title)}</h3>')
                page.value_table([(p[len(f'/analyses/{i}/'):], p, v)
                                  for p, v in flat(a, f"/analyses/{i}")])
                page.add("</div>")
            continue
        page.add(f'<div class="card"><h3>{html.escape(key.replace("_", " "))}</h3>')
        page.value_table([(p[len(key) + 2:] or key, p, v) for p, v in flat(value, "/" + key)])
        page.add("</div>")


SCRIPT = r"""
// Sortable tables: a click on a column's title sorts the rows by it (numbers as numbers).
for (const table of document.querySelectorAll("table.sortable")) {
  table.querySelectorAll("th").forEach((th, column) => {
    th.addEventListener("click", () => {
      const body = table.tBodies[0];
      const rows = Array.from(body.rows);
      const up = th.getAttribute("aria-sort") !== "ascending";
      table.querySelectorAll("th").forEach((h) => h.removeAttribute("aria-sort"));
      th.setAttribute("aria-sort", up ? "ascending" : "descending");
      const key = (r) => r.cells[column] ? r.cells[column].textContent : "";
      const numeric = rows.every((r) => key(r) === "" || !isNaN(Number(key(r))) ||
                                        ["nan", "inf", "-inf", "null"].includes(key(r)));
      const value = (r) => {
        const t = key(r);
        if (!numeric) return t;
        if (t === "inf") return Infinity;
        if (t === "-inf") return -Infinity;
        return t === "nan" || t === "null" || t === "" ? NaN : Number(t);
      };
      rows.sort((a, b) => {
        const x = value(a), y = value(b);
        if (numeric) {
          if (isNaN(x)) return 1;
          if (isNaN(y)) return -1;
          return up ? x - y : y - x;
        }
        return up ? x.localeCompare(y) : y.localeCompare(x);
      });
      rows.forEach((r) => body.appendChild(r));
    });
  });
}
"""

STYLE = """
body { font-family: system-ui, sans-serif; margin: 0; color: #222; }
header { background: #23395d; color: white; padding: 14px 24px; }
header h1 { margin: 0 0 4px 0; font-size: 22px; }
nav { padding: 6px 24px; background: #e8edf4; position: sticky; top: 0; z-index: 2; }
nav a { margin-right: 14px; color: #23395d; }
main { padding: 0 24px 40px 24px; max-width: 1200px; }
table { border-collapse: collapse; margin: 6px 0 14px 0; font-size: 13px; }
th, td { border: 1px solid #ccd; padding: 3px 8px; text-align: left; }
th { background: #eef1f6; cursor: pointer; }
th[aria-sort=ascending]::after { content: " \\25B2"; }
th[aria-sort=descending]::after { content: " \\25BC"; }
td.v { font-family: ui-monospace, monospace; }
.scroll { overflow: auto; max-height: 480px; }
.status-ok { color: #1a7f37; } .status-bad { color: #c62828; }
.note { color: #666; font-size: 13px; margin: 2px 0; }
figure { margin: 12px 0 22px 0; } figure img { max-width: 100%; border: 1px solid #dde; }
figcaption { color: #444; font-size: 13px; }
#viewer-canvas { width: 100%; border: 1px solid #ccd; }
.controls { margin: 6px 0; } .controls > * { margin-right: 10px; }
ul.warnings li { margin: 3px 0; }
.card { display: inline-block; vertical-align: top; margin: 0 18px 6px 0; }
"""


def build(results, bundle, bodies_asked, output):
    summary = read_json(os.path.join(results, "summary.json"), "the summary")
    if not isinstance(summary, dict):
        raise BadInput(f"{results}/summary.json is not the summary of a beamrail run")
    study_path = os.path.join(results, "resolved_study.json")
    study = read_json(study_path, "the study record") if os.path.exists(study_path) else {}
    units = units_of(study)
    kind = summary.get("type", "single")
    name = summary.get("study", os.path.basename(os.path.abspath(results)))
    plot_dir = os.path.join(results, "plots")
    os.makedirs(plot_dir, exist_ok=True)
    figures = []  # (path, caption)
    notes = []

    def png(stem):
        return os.path.join(plot_dir, stem.replace("/", "_") + ".png")

    contents = vtkfiles.contents(results)
    vtk_entries = {e["name"]: e for e in (contents or {}).get("analyses", [])}

    # Plots from the tables.
    if kind == "single":
        for a in summary.get("analyses", []):
            tables = [os.path.join(results, t) for t in a.get("tables", [])]
            tables = [t for t in tables if os.path.exists(t)]
            an = a.get("name", a.get("type"))
            if a.get("type") == "transient" and tables:
                header, rows = read_csv(tables[0])
                if not rows:
                    continue
                data = np.array([[float(x) for x in r] for r in rows])
                table = {h: data[:, i] for i, h in enumerate(header)}
                bodies = [h[:-2] for h in header if h.endswith(".x")]
                moved = sorted(bodies, key=lambda b: -max(
                    float(np.abs(table[f"{b}.{c}"] - table[f"{b}.{c}"][0]).max()) for c in "xyz"))
                chosen = [b for b in bodies_asked if b in bodies] if bodies_asked else moved[:3]
                missing = [b for b in bodies_asked or [] if b not in bodies]
                if missing:
                    notes.append(f"--bodies: {', '.join(missing)} not in {tables[0]}")
                if chosen:
                    c1, c2 = plots.transient(table, chosen, png(f"{an}.motion"),
                                             png(f"{an}.energy"), an)
                    figures += [(png(f"{an}.motion"), c1), (png(f"{an}.energy"), c2)]
            if a.get("type") == "modal":
                modes = [t for t in tables if t.endswith("modes.csv")]
                if modes:
                    figures.append((png(f"{an}.frequencies"), plots.frequencies(
                        read_dicts(modes[0]), png(f"{an}.frequencies"), an)))
            if a.get("type") == "buckling":
                factors = [t for t in tables if t.endswith("buckling.csv")]
                rows = read_dicts(factors[0]) if factors else []
                if rows:
                    figures.append((png(f"{an}.factors"),
                                    plots.factors(rows, png(f"{an}.factors"), an)))
    elif kind == "sweep" and os.path.exists(os.path.join(results, "samples.csv")):
        rows = read_dicts(os.path.join(results, "samples.csv"))
        variables = [v["name"] for v in (study.get("study") or {}).get("variables", [])]
        header = read_csv(os.path.join(results, "samples.csv"))[0]
        responses = header[1 + len(variables):header.index("status")] if "status" in header else []
        if rows and variables:
            caps = plots.sweep(rows, variables, responses, units, png("sweep.responses"),
                               png("sweep.pairs") if 2 <= len(variables) <= 4 else None, name)
            figures.append((png("sweep.responses"), caps[0]))
            if len(caps) > 1:
                figures.append((png("sweep.pairs"), caps[1]))
    elif kind == "optimize" and os.path.exists(os.path.join(results, "history.csv")):
        rows = read_dicts(os.path.join(results, "history.csv"))
        plan = study.get("study") or {}
        constraints = []
        for c in plan.get("constraints", []):
            for op in ("<=", ">=", "abs<="):
                if op in c:
                    constraints.append((c["response"], op, float(c[op])))
        goal = plan.get("objective", {})
        objective = goal.get("minimize") or goal.get("maximize")
        label = units.get(objective, "-") if objective else "-"
        if rows:
            figures.append((png("optimize.convergence"), plots.convergence(
                rows, label, constraints, png("optimize.convergence"), name)))
    elif kind == "work_precision" and os.path.exists(os.path.join(results,
                                                                  "work_precision.csv")):
        script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                              "plot_work_precision")
        subprocess.run([script, results, png("work_precision")], check=True,
                       stdout=subprocess.DEVNULL)
        figures.append((png("work_precision"), f"{name}: error against wall time per method, "
                        "tolerances marked (work_precision.csv)"))

    # Plots and the 3-D view from the VTK files.
    views = []
    design = (contents or {}).get("design")
    prefix = ""
    if design:
        which = design.get("which")
        prefix = ("best design: " if which == "best" else
                  f"design {design.get('index', '')}{design.get('start', '')}"
                  f"{':' + str(design.get('evaluation')) if 'evaluation' in design else ''}: "
                  if which == "row" else "study's own design: ")
    for entry in vtk_entries.values():
        an = entry["name"]
        coll = vtkfiles.Collection(os.path.join(results, "vtk", entry["pvd"]))
        if not coll.frames:
            continue
        views.append(view_of(results, entry, prefix))
        if entry["type"] == "static" and len(coll.frames) >= 2:
            e0, e1 = coll.read(0, "elements"), coll.read(1, "elements")
            b0, b1 = coll.read(0, "bodies"), coll.read(1, "bodies")
            lines = e0.cells.get("Lines", [])
            figures.append((png(f"{an}.deformed"), plots.deformed(
                (e0.points, lines, b0.points), (e1.points, lines, b1.points),
                png(f"{an}.deformed"), prefix + an, float(entry.get("scene_size", 1.0)))))
        if entry["type"] in ("modal", "buckling") and entry.get("modes"):
            first = coll.read(0, "elements")
            base = (first.points, first.cells.get("Lines", []), coll.read(0, "bodies").points)
            modes = []
            for m in entry["modes"]:
                e, b = coll.read(m["first_frame"], "elements"), coll.read(m["first_frame"],
                                                                          "bodies")
                title = (f"mode {m['mode']}: {m['frequency_hz']:.5g} Hz"
                         if entry["type"] == "modal" else
                         f"mode {m['mode']}: factor {m['factor']:.5g}")
                modes.append((title, e.point_data["shape"], b.point_data["shape"],
                              m["amplitude"]))
            label = "mode shapes" if entry["type"] == "modal" else "buckling shapes"
            figures.append((png(f"{an}.shapes"), plots.shapes(base, modes, png(f"{an}.shapes"),
                                                              prefix + an, label)))

    # The page.
    page = Page()
    status = summary.get("status", "")
    summary_sections(page, summary, units)
    page.section("view", "3-D view")
    if views:
        what = {"best": "the best design", "row": "the design chosen with --design",
                "own": "the study's own design"}.get((design or {}).get("which"), "")
        page.add('<p class="note">Drawn from the VTK files in vtk/' +
                 (f" ({html.escape(what)})" if what else "") +
                 ": bodies as boxes of their extent with a line to each attachment point, beams "
                 "(orange) and rails (green) as curves through their deformed shape"
                 + (" (a static analysis colours them by axial force: red tension, blue "
                    "compression)" if any(v["type"] == "static" for v in views) else "") +
                 ". Drag to orbit, wheel to zoom, right-drag to pan.</p>")
        page.add('<div class="controls"><select id="viewer-view"></select>'
                 '<select id="viewer-mode"></select><button id="viewer-play">Play</button>'
                 '<input type="range" id="viewer-frame" min="0" max="0" value="0">'
                 '<label>scale <input type="range" id="viewer-scale"></label>'
                 '<span id="viewer-label"></span></div><div id="viewer-canvas"></div>')
    else:
        page.add("<p>No 3-D view: the results hold no VTK files. Run the study with "
                 "<code>--vtk</code> (or <code>\"outputs\": {\"vtk\": true}</code>) and make the "
                 "report again.</p>")
        if kind == "single":
            notes.append("no vtk/ folder: no 3-D view, no shape plots (run with --vtk)")
    page.section("plots", f"Plots ({len(figures)})")
    for path, caption in figures:
        page.figure(path, caption)
    if not figures:
        page.add("<p>No plots for these results.</p>")
    detail_sections(page, summary)
    page.section("tables", "Tables")
    shown = []
    if kind == "single":
        for a in summary.get("analyses", []):
            shown += [t for t in a.get("tables", []) if os.path.exists(os.path.join(results, t))]
    else:
        shown = [t for t in ("samples.csv", "history.csv", "work_precision.csv",
                             "sensitivities.csv") if os.path.exists(os.path.join(results, t))]
    best = os.path.join(results, "best.json")
    if kind == "optimize" and os.path.exists(best):
        b = read_json(best, "best.json")
        page.add("<h3>best.json: constraints of the best design</h3>")
        cons = b.get("constraints", [])
        if cons:
            keys = list(cons[0].keys())
            page.add('<table class="sortable data" id="best-constraints"><thead><tr>' +
                     "".join(f"<th>{html.escape(k)}</th>" for k in keys) + "</tr></thead><tbody>" +
                     "".join("<tr>" + "".join(f"<td>{html.escape(text_of(c.get(k)))}</td>"
                                              for k in keys) + "</tr>" for c in cons) +
                     "</tbody></table>")
    for t in shown:
        page.csv_table(os.path.join(results, t), t)
    if not shown:
        page.add("<p>No tables.</p>")

    index = [{"file": os.path.relpath(path, results), "caption": caption,
              "axes": plots.AXES.get(path, [])} for path, caption in figures]
    if os.path.exists(os.path.join(plot_dir, "work_precision.png")):
        for item in index:
            if item["file"].endswith("work_precision.png"):
                item["axes"] = [["wall time [s]",
                                 "error [-] (largest body-centre distance / largest motion)"]]
    with open(os.path.join(plot_dir, "index.json"), "w") as f:
        json.dump(index, f, indent=1)
    data = json.dumps({"views": views}, separators=(",", ":")).replace("</", "<\\/")
    with open(bundle) as f:
        script = f.read().replace("</script", "<\\/script")
    ok = status == "ok"
    nav = "".join(f'<a href="#{a}">{html.escape(t)}</a>' for a, t in page.nav)
    document = f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{html.escape(str(name))}: beamrail report</title>
<style>{STYLE}</style></head>
<body data-study="{html.escape(str(name))}" data-kind="{html.escape(kind)}">
<header><h1>{html.escape(str(name))}</h1>
<div>{html.escape(kind if kind != "single" else "single run")} &middot; status
<b class="{'status-ok' if ok else 'status-bad'}" id="status" data-pointer="/status">{html.escape(text_of(status))}</b>
&middot; {html.escape(str(summary.get("file", "")))}</div></header>
<nav>{nav}</nav>
<main>
{"".join(page.parts)}
</main>
<script id="beamrail-scene" type="application/json">{data}</script>
<script>{SCRIPT}</script>
<script>{script}</script>
</body></html>
"""
    tmp = output + ".partial"
    with open(tmp, "w") as f:
        f.write(document)
    os.replace(tmp, output)
    return output, figures, notes


def main(argv):
    parser = argparse.ArgumentParser(prog="scripts/report", description=__doc__)
    parser.add_argument("results")
    parser.add_argument("--bundle", required=True)
    parser.add_argument("--bodies", default="")
    parser.add_argument("-o", "--output", default="")
    args = parser.parse_args(argv)
    if not os.path.isdir(args.results):
        raise BadInput(f"{args.results} is not a folder (give the results folder of a beamrail "
                       "run)")
    if not os.path.exists(os.path.join(args.results, "summary.json")):
        raise BadInput(f"{args.results} holds no summary.json: it is not the results folder of "
                       "a beamrail run")
    output = args.output or os.path.join(args.results, "report.html")
    bodies = [b for b in args.bodies.split(",") if b]
    path, figures, notes = build(args.results, args.bundle, bodies, output)
    for n in notes:
        print(f"report: {n}", file=sys.stderr)
    print(path)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except BadInput as e:
        print(f"scripts/report: {e}", file=sys.stderr)
        sys.exit(2)
