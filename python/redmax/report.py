"""The summary report of a batch study (docs/python.md §3): ``DIR/report.md`` and one figure per
(numeric column, grid flag) in ``DIR/report/``.

Each figure plots a numeric column of results.csv (``wall_s`` and the commands' summary figures
that vary between cells) against the values of one grid flag, one series per trial, every ok cell
a point (cells that differ in the other flags share an x). Figures are SVG drawn by gnuplot
(Debian's gnuplot-nox, installed by scripts/setup) from a script that carries the data inline;
each is written beside its target and renamed into place. Without gnuplot the report says so and
lists the tables only. Only the standard library is used, like redmax.study.
"""
import os
import re
import shutil
import subprocess

REPORT = "report.md"
FIGURE_DIR = "report"


def _number(text):
    try:
        x = float(text)
    except (TypeError, ValueError):
        return None
    return x if x == x and abs(x) != float("inf") else None


def _slug(text):
    return re.sub(r"[^A-Za-z0-9._+-]", "_", text.lstrip("-"))


def numeric_columns(rows):
    """wall_s and the summary figures that are numbers in every ok cell and differ between them."""
    ok = [r for r in rows if r["status"] == "ok"]
    names = ["wall_s"]
    for r in ok:
        for k in r.get("figures", {}):
            if k not in names:
                names.append(k)
    out = []
    for k in names:
        vals = [_number(r["wall_s"] if k == "wall_s" else r.get("figures", {}).get(k)) for r in ok]
        if ok and all(v is not None for v in vals) and len(set(vals)) > 1:
            out.append(k)
    return out


def figure_data(rows, flags, column, flag):
    """(x labels or None, {trial: [(x, y), ...]}): x is the grid value when every value of the flag
    is a number, else its index among the flag's values (the labels then name them)."""
    values = []
    for r in rows:
        v = r["grid"].get(flag, "")
        if v not in values:
            values.append(v)
    numeric = all(_number(v) is not None for v in values)
    series = {}
    for r in rows:
        if r["status"] != "ok":
            continue
        v = r["grid"].get(flag, "")
        x = _number(v) if numeric else values.index(v)
        y = _number(r["wall_s"] if column == "wall_s" else r.get("figures", {}).get(column))
        series.setdefault(r["trial"], []).append((x, y))
    return (None if numeric else values), series


def find_gnuplot():
    """gnuplot from $REDMAX_GNUPLOT ("none" disables plots) or PATH; None when absent."""
    hint = os.environ.get("REDMAX_GNUPLOT", "")
    if hint == "none":
        return None
    return shutil.which(hint or "gnuplot")


def gnuplot_script(title, xlabel, ylabel, labels, series, target):
    """A gnuplot script that draws `series` ({name: [(x, y)]}) as points into the SVG `target`."""
    lines = ["set terminal svg noenhanced size 640,400 font 'sans,10' background '#ffffff'",
             f"set output '{target}'", f"set title '{title}'", f"set xlabel '{xlabel}'", f"set ylabel '{ylabel}'",
             "set key outside right", "set grid", "set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05"]
    if labels is not None:
        tics = ", ".join(f"'{v}' {i}" for i, v in enumerate(labels))
        lines.append(f"set xtics ({tics})")
    plots = []
    for i, (name, pts) in enumerate(series.items()):
        lines.append(f"$d{i} << EOD")
        lines += [f"{x!r} {y!r}" for x, y in pts]
        lines.append("EOD")
        plots.append(f"$d{i} using 1:2 with points pointtype 7 title '{name}'")
    lines.append("plot " + ", ".join(plots))
    return "\n".join(lines) + "\n"


def _plot(gnuplot, script, target):
    tmp = target + ".tmp.svg"
    script = script.replace(f"set output '{target}'", f"set output '{tmp}'")
    p = subprocess.run([gnuplot], input=script, capture_output=True, text=True)
    if p.returncode != 0 or not os.path.exists(tmp):
        if os.path.exists(tmp):
            os.remove(tmp)
        return p.stderr.strip() or f"gnuplot exit code {p.returncode}"
    os.replace(tmp, target)
    return None


def _md_cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def write_report(out_dir, rows, flags, elapsed_s=None):
    """Writes out_dir/report.md (and the figures into out_dir/report/); returns the figure paths."""
    fig_dir = os.path.join(out_dir, FIGURE_DIR)
    gnuplot = find_gnuplot()
    columns = numeric_columns(rows)
    varying = [f for f in flags if len({r["grid"].get(f) for r in rows}) > 1]
    figures, notes = [], []
    if gnuplot and columns and varying:
        os.makedirs(fig_dir, exist_ok=True)
        for c in columns:
            for f in varying:
                labels, series = figure_data(rows, flags, c, f)
                if not series:
                    continue
                name = f"{_slug(c)}_vs_{_slug(f)}.svg"
                target = os.path.join(fig_dir, name)
                err = _plot(gnuplot, gnuplot_script(f"{c} against {f}", f, c, labels, series, target), target)
                if err:
                    notes.append(f"{name}: {err}")
                else:
                    figures.append((c, f, os.path.join(FIGURE_DIR, name)))
    elif not gnuplot:
        notes.append("no figures: gnuplot not found (Debian gnuplot-nox; $REDMAX_GNUPLOT)")

    ok = sum(r["status"] == "ok" for r in rows)
    md = ["# Batch study", ""]
    summary = f"{len(rows)} cells: {ok} ok, {len(rows) - ok} errors"
    if elapsed_s is not None:
        summary += f"; {elapsed_s:.2f} s wall (measured)"
    md += [summary + ". The table: `results.csv`.", ""]
    fig_cols = []
    for r in rows:
        for k in r.get("figures", {}):
            if k not in fig_cols:
                fig_cols.append(k)
    header = ["trial"] + flags + ["status", "wall_s"] + fig_cols + ["output / error"]
    md += ["| " + " | ".join(_md_cell(h) for h in header) + " |", "|" + "---|" * len(header)]
    for r in rows:
        cells = [r["trial"]] + [r["grid"].get(f, "") for f in flags] + [r["status"], f"{r['wall_s']:.3f}"]
        cells += [r.get("figures", {}).get(k, "") for k in fig_cols]
        cells.append(r["output"] if r["status"] == "ok" else r["error"])
        md.append("| " + " | ".join(_md_cell(c) for c in cells) + " |")
    md.append("")
    if figures:
        md += ["## Figures", "", "Each ok cell is a point; one series per trial.", ""]
        for c, f, rel in figures:
            md += [f"### {c} against {f}", "", f"![{c} against {f}]({rel})", ""]
    for n in notes:
        md.append(f"- {n}")
    text = "\n".join(md) + "\n"
    tmp = os.path.join(out_dir, REPORT + f".tmp-{os.getpid()}")
    with open(tmp, "w") as fh:
        fh.write(text)
    os.replace(tmp, os.path.join(out_dir, REPORT))
    return [os.path.join(out_dir, rel) for _, _, rel in figures]
