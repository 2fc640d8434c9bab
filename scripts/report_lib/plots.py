"""The report's plots (matplotlib, PNG): transient body coordinates and energy, modal frequencies and
shapes, buckling factors and shapes, static deformed shapes, sweep responses against variables with
a pairwise view, optimization convergence. Each function writes one PNG and returns its caption."""

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.patches  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

DPI = 110
DIRECTION_COLOURS = {"x": "#1f77b4", "y": "#ff7f0e", "z": "#2ca02c", "rx": "#9467bd",
                     "ry": "#8c564b", "rz": "#e377c2", "none": "#7f7f7f"}


# Per PNG written: the labels of its axes (x, y and for 3-D z), for plots/index.json.
AXES = {}


def _save(fig, path, tight=True):
    if tight:
        fig.tight_layout()
    AXES[path] = [[label for label in [a.get_xlabel(), a.get_ylabel()] +
                   ([a.get_zlabel()] if hasattr(a, "get_zlabel") else []) if label]
                  for a in fig.axes if a.get_xlabel() or a.get_ylabel()]
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def nice_factor(x):
    """The smallest of 1, 2, 5 x 10^k at least x (1 for x <= 1)."""
    if not x > 1:
        return 1.0
    k = math.floor(math.log10(x))
    for m in (1, 2, 5, 10):
        if m * 10 ** k >= x * (1 - 1e-12):
            return float(m * 10 ** k)
    return float(10 ** (k + 1))


def transient(table, bodies, path_motion, path_energy, name):
    """table: dict column -> numpy array (timeseries.csv). bodies: the bodies drawn."""
    t = table["t"]
    fig, axes = plt.subplots(len(bodies), 1, figsize=(7.5, 1.2 + 2.2 * len(bodies)), sharex=True,
                             squeeze=False)
    for ax, body in zip(axes[:, 0], bodies):
        for c, colour in zip("xyz", ("#1f77b4", "#ff7f0e", "#2ca02c")):
            v = table[f"{body}.{c}"]
            ax.plot(t, v - v[0], color=colour, label=f"{c} - {c}(0)")
        ax.set_ylabel(f"{body}\ndisplacement [m]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    axes[-1, 0].set_xlabel("t [s]")
    axes[0, 0].set_title(f"{name}: centre of mass of the bodies that move most")
    _save(fig, path_motion)
    e = table["energy"]
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.5, 5), sharex=True)
    a1.plot(t, e, color="#333333")
    a1.set_ylabel("energy E [J]")
    a1.set_title(f"{name}: total energy (kinetic + elastic + gravity)")
    a1.grid(True, alpha=0.3)
    a2.plot(t, e - e[0], color="#d62728")
    a2.set_ylabel("E - E(0) [J]")
    a2.set_xlabel("t [s]")
    a2.grid(True, alpha=0.3)
    _save(fig, path_energy)
    return (f"{name}: displacement of the centres of {', '.join(bodies)} from t = 0 "
            "(timeseries.csv)", f"{name}: total energy and its change since t = 0")


def frequencies(rows, path, name):
    """rows: modes.csv rows (dicts). Elastic modes as bars, coloured by dominant direction."""
    elastic = [r for r in rows if r["kind"] != "rigid"]
    fig, ax = plt.subplots(figsize=(7.5, 4))
    modes = [int(r["mode"]) for r in elastic]
    f = [float(r["frequency_hz"]) for r in elastic]
    colours = [DIRECTION_COLOURS.get(r["dominant"], "#7f7f7f") for r in elastic]
    ax.bar(modes, f, color=colours)
    for m, v in zip(modes, f):
        ax.annotate(f"{v:.4g}", (m, v), ha="center", va="bottom", fontsize=8)
    seen = {}
    for r in elastic:
        seen.setdefault(r["dominant"], DIRECTION_COLOURS.get(r["dominant"], "#7f7f7f"))
    ax.legend(handles=[matplotlib.patches.Patch(color=c, label=f"dominant {d}")
                       for d, c in seen.items()], fontsize=8)
    ax.set_xlabel("elastic mode [-]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_xticks(modes)
    ax.set_title(f"{name}: natural frequencies")
    ax.grid(True, axis="y", alpha=0.3)
    _save(fig, path)
    rigid = len(rows) - len(elastic)
    return (f"{name}: the elastic modes' frequencies, coloured by the direction of their largest "
            f"effective mass (modes.csv)" + (f"; {rigid} rigid modes not drawn" if rigid else ""))


def factors(rows, path, name):
    fig, ax = plt.subplots(figsize=(7.5, 3.6))
    modes = [int(r["mode"]) for r in rows]
    f = [float(r["factor"]) for r in rows]
    ax.bar(modes, f, color="#9467bd")
    for m, v in zip(modes, f):
        ax.annotate(f"{v:.4g}", (m, v), ha="center", va="bottom", fontsize=8)
    ax.axhline(1.0, color="#d62728", lw=1, ls="--", label="factor 1: the loads as given")
    ax.set_xlabel("buckling mode [-]")
    ax.set_ylabel("load factor [-]")
    ax.set_xticks(modes)
    ax.legend(fontsize=8)
    ax.set_title(f"{name}: buckling load factors")
    ax.grid(True, axis="y", alpha=0.3)
    _save(fig, path)
    return f"{name}: the lowest buckling load factors (buckling.csv)"


def _equal_3d(ax, points):
    lo, hi = points.min(axis=0), points.max(axis=0)
    span = max(float((hi - lo).max()), 1e-12)
    centre = (lo + hi) / 2
    for set_lim, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
        set_lim(c - span / 2, c + span / 2)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x [m]", fontsize=8)
    ax.set_ylabel("y [m]", fontsize=8)
    ax.set_zlabel("z [m]", fontsize=8)
    ax.tick_params(labelsize=7)


def _draw(ax, curves, centres, colour, style="-", width=1.6, alpha=1.0, marker=True):
    for c in curves:
        ax.plot(c[:, 0], c[:, 1], c[:, 2], style, color=colour, lw=width, alpha=alpha)
    if marker and len(centres):
        ax.scatter(centres[:, 0], centres[:, 1], centres[:, 2], s=8, color=colour, alpha=alpha)


def _curves(points, lines):
    return [points[np.asarray(c)] for c in lines]


def deformed(undeformed, deformed_, path, name, size):
    """undeformed, deformed_: (curve points, element lines, body centres)."""
    (p0, lines, c0), (p1, _, c1) = undeformed, deformed_
    largest = float(np.abs(p1 - p0).max()) if len(p0) else 0.0
    scale = nice_factor(0.05 * size / largest) if largest > 0 else 1.0
    fig = plt.figure(figsize=(7.5, 6))
    ax = fig.add_subplot(projection="3d")
    _draw(ax, _curves(p0, lines), c0, "#999999", "--", 1.0)
    shown = p0 + scale * (p1 - p0)
    _draw(ax, _curves(shown, lines), c0 + scale * (c1 - c0), "#d62728")
    _equal_3d(ax, np.vstack([p0, shown]) if len(p0) else np.vstack([c0, c1]))
    ax.set_title(f"{name}: deformed (red, displacements x {scale:g}) and undeformed (grey)")
    _save(fig, path)
    return (f"{name}: the equilibrium (red) over the undeformed scene (grey), displacements "
            f"magnified {scale:g} times; largest displacement of a drawn point "
            f"{largest:.4g} m")


def shapes(base, modes, path, name, label):
    """base: (curve points, lines, centres) of the state linearized about; modes: list of
    (title, curve shape, centre shape, amplitude)."""
    p0, lines, c0 = base
    n = min(len(modes), 6)
    cols = 3 if n > 4 else 2 if n > 1 else 1
    rows = math.ceil(n / cols)
    fig = plt.figure(figsize=(4.2 * cols, 3.9 * rows))
    for k in range(n):
        title, shape, centre_shape, amplitude = modes[k]
        ax = fig.add_subplot(rows, cols, k + 1, projection="3d")
        _draw(ax, _curves(p0, lines), c0, "#999999", "--", 0.8, marker=False)
        for sign, alpha in ((1, 1.0), (-1, 0.35)):
            p = p0 + sign * amplitude * shape
            _draw(ax, _curves(p, lines), c0 + sign * amplitude * centre_shape, "#1f77b4",
                  width=1.4, alpha=alpha, marker=sign > 0)
        _equal_3d(ax, np.vstack([p0, p0 + amplitude * shape, p0 - amplitude * shape]))
        ax.set_title(title, fontsize=9)
    fig.suptitle(f"{name}: {label}")
    _save(fig, path)
    more = f" (the first {n} of {len(modes)})" if len(modes) > n else ""
    return (f"{name}: {label}{more}, drawn at the amplitude of the VTK animation (dark: +, "
            "light: -) over the state linearized about (grey)")


def sweep_points(rows, var, resp):
    """One panel of a sweep's responses: (variable values, response values) of the ok rows
    without warnings ("ok"), of those with ("warned"), of the others with a value ("failed": a
    design that failed after this response was computed), and the variable values of the rows
    without this response ("no_value")."""
    def value(r, col):
        try:
            return float(r[col])
        except (TypeError, ValueError):
            return math.nan

    out = {"ok": ([], []), "warned": ([], []), "failed": ([], []), "no_value": []}
    for r in rows:
        x, y = value(r, var), value(r, resp)
        if not math.isfinite(y):
            out["no_value"].append(x)
            continue
        kind = ("failed" if r["status"] != "ok" else
                "warned" if int(r["warnings"]) > 0 else "ok")
        out[kind][0].append(x)
        out[kind][1].append(y)
    return out


def sweep(rows, variables, responses, units, path_responses, path_pairs, name):
    """rows: samples.csv as dicts. Each response against each variable; a pairwise view of the
    variables (2 to 4 of them) coloured by the first response."""
    def values(col, subset):
        return np.array([float(r[col]) for r in subset])

    ok = [r for r in rows if r["status"] == "ok" and int(r["warnings"]) == 0]
    warned = [r for r in rows if r["status"] == "ok" and int(r["warnings"]) > 0]
    failed = [r for r in rows if r["status"] != "ok"]
    shown_r, shown_v = responses[:6], variables[:6]
    fig, axes = plt.subplots(len(shown_r), len(shown_v), figsize=(3.4 * len(shown_v) + 0.8,
                                                                   2.6 * len(shown_r) + 0.6),
                             squeeze=False)
    legend = {}
    for i, resp in enumerate(shown_r):
        for j, var in enumerate(shown_v):
            ax = axes[i, j]
            points = sweep_points(rows, var, resp)
            if len(points["ok"][0]):
                ax.plot(*points["ok"], "o", ms=4, color="#1f77b4", label="ok")
            if len(points["warned"][0]):
                ax.plot(*points["warned"], "s", ms=4, color="#ff7f0e", label="ok with warnings")
            if len(points["failed"][0]):
                ax.plot(*points["failed"], "x", ms=6, color="#d62728",
                        label="failed, invalid or timeout")
            if len(points["no_value"]):
                # Rows without this response: on the x axis itself (axes coordinates), so that
                # no mark sits at a value another design has.
                ax.plot(points["no_value"], [0.0] * len(points["no_value"]), "x", ms=6,
                        color="#7f7f7f", clip_on=False, transform=ax.get_xaxis_transform(),
                        label="no value (on the x axis)")
            ax.set_xlabel(f"{var} [{units.get(var, '-')}]", fontsize=8)
            ax.set_ylabel(f"{resp} [{units.get(resp, '-')}]", fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(True, alpha=0.3)
            for h, label in zip(*ax.get_legend_handles_labels()):
                legend.setdefault(label, h)
    handles, labels = list(legend.values()), list(legend)
    top = 1 - 0.75 / fig.get_figheight()
    fig.suptitle(f"{name}: each response against each variable", y=0.995, fontsize=10)
    fig.legend(handles, labels, loc="upper center", ncol=3, fontsize=8,
               bbox_to_anchor=(0.5, 1 - 0.3 / fig.get_figheight()))
    fig.tight_layout(rect=(0, 0, 1, top))
    _save(fig, path_responses, tight=False)
    captions = [f"{name}: each response against each design variable of samples.csv "
                f"({len(ok)} ok, {len(warned)} with warnings, {len(failed)} failed or invalid)"]
    if not 2 <= len(variables) <= 4 or not path_pairs:
        return captions
    n = len(variables)
    colour_by = responses[0] if responses else None
    fig, axes = plt.subplots(n - 1, n - 1, figsize=(3.6 * (n - 1) + 1.6, 3.2 * (n - 1) + 0.5),
                             squeeze=False, layout="constrained")
    scatter = None
    for i in range(1, n):
        for j in range(n - 1):
            ax = axes[i - 1, j]
            if j >= i:
                ax.axis("off")
                continue
            good = ok + warned
            if good:
                c = values(colour_by, good) if colour_by else "#1f77b4"
                scatter = ax.scatter(values(variables[j], good), values(variables[i], good), c=c,
                                     cmap="viridis", s=22)
            if failed:
                ax.plot(values(variables[j], failed), values(variables[i], failed), "x",
                        color="#d62728", ms=6)
            ax.set_xlabel(f"{variables[j]} [{units.get(variables[j], '-')}]", fontsize=8)
            ax.set_ylabel(f"{variables[i]} [{units.get(variables[i], '-')}]", fontsize=8)
            ax.tick_params(labelsize=7)
    if scatter is not None and colour_by:
        fig.colorbar(scatter, ax=axes, label=f"{colour_by} [{units.get(colour_by, '-')}]")
    fig.suptitle(f"{name}: designs by pairs of variables", fontsize=10)
    _save(fig, path_pairs, tight=False)
    captions.append(f"{name}: the designs by pairs of variables, coloured by {colour_by}; red x: "
                    "failed, invalid or timeout")
    return captions


def convergence(rows, objective_label, constraints, path, name):
    """rows: history.csv as dicts; constraints: list of (response, op, bound)."""
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.5, 6), sharex=True)
    starts = sorted({int(r["start"]) for r in rows})
    for s in starts:
        rs = [r for r in rows if int(r["start"]) == s]
        e = np.array([int(r["evaluation"]) for r in rs])
        obj = np.array([float(r["objective"]) for r in rs])
        usable = obj < 1e29
        a1.plot(e[usable], obj[usable], "o-", ms=3, lw=1, label=f"start {s}")
        feasible = np.array([r["feasible"] == "1" for r in rs]) & usable
        a1.plot(e[feasible], obj[feasible], "o", ms=5, mfc="none", color="#2ca02c")
        worst = []
        for r in rs:
            v = 0.0
            for resp, op, bound in constraints:
                x = float(r[resp])
                if not math.isfinite(x):
                    v = math.inf
                    continue
                excess = x - bound if op == "<=" else bound - x if op == ">=" else abs(x) - bound
                v = max(v, excess / (abs(bound) if bound != 0 else 1.0))
            worst.append(v)
        worst = np.array(worst)
        shown = np.isfinite(worst)
        a2.semilogy(e[shown], np.maximum(worst[shown], 1e-16), "o-", ms=3, lw=1,
                    label=f"start {s}")
    a1.set_ylabel(f"objective [{objective_label}]")
    a1.set_title(f"{name}: objective (green rings: feasible designs)")
    a1.grid(True, alpha=0.3)
    a1.legend(fontsize=8)
    if not constraints:
        a2.text(0.5, 0.5, "no constraints", ha="center", va="center", transform=a2.transAxes)
    a2.axhline(1e-9, color="#2ca02c", lw=1, ls="--", label="feasible below 1e-9")
    a2.set_ylabel("worst constraint violation\n(relative to |bound|) [-]")
    a2.set_xlabel("design number [-] (evaluation of its start)")
    a2.grid(True, which="both", alpha=0.3)
    a2.legend(fontsize=8)
    _save(fig, path)
    return (f"{name}: the objective and the worst constraint violation of each design of "
            "history.csv, per start (a violation at or below 1e-16 is drawn at 1e-16)")
