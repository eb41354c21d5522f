#!/usr/bin/python3
"""Plots of apps/bench's results (docs/bench/README.md): error against run time, and run time
against N.

Usage: /usr/bin/python3 scripts/plot_bench.py DIR
Reads DIR/results.json, writes DIR/error_vs_time.png and DIR/scaling.png. Needs Debian's
python3-matplotlib (scripts/install-deps.sh).
"""
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# Ours in blues and greens, OpenCV in warm colours and greys; one marker per method.
STYLE = {
    "ours-start": ("#9ecae1", "v"),
    "ours-refine": ("#08519c", "o"),
    "ours-default": ("#31a354", "s"),
    "ours-auto": ("#006d2c", "P"),
    "cv-calib-80deg": ("#d62728", "D"),
    "cv-calib-ourstart": ("#ff7f0e", "^"),
    "cv-sqpnp": ("#7f7f7f", "P"),
    "cv-iterative": ("#bcbd22", "X"),
}
# The headline configuration: a projector (principal point at the bottom edge), non-planar points.
OBJECT, CAMERA = "cloud", "projector"


def finite(v):
    return v is not None and math.isfinite(v) and v > 0


def series(cells, method, sigma, key, obj=OBJECT, camera=CAMERA):
    """(n, median time in ms, value of `key`) per N, where both are positive and finite."""
    rows = sorted(
        (c for c in cells
         if c["method"] == method and c["sigma_px"] == sigma and c["object"] == obj
         and c["camera"] == camera),
        key=lambda c: c["n"])
    return [(c["n"], c["time_median_us"] / 1e3, c[key]) for c in rows
            if finite(c["time_median_us"]) and finite(c[key])]


def error_vs_time(data, path):
    cells, methods = data["cells"], [m["name"] for m in data["methods"]]
    sigmas = sorted({c["sigma_px"] for c in cells if c["sigma_px"] > 0})
    panels = [("focal_err_median_pct", "median focal error (%)", OBJECT, "non-planar points"),
              ("rotation_err_median_deg", "median rotation error (°)", OBJECT, "non-planar points"),
              ("focal_err_median_pct", "median focal error (%)", "plane", "planar points")]
    fig, axes = plt.subplots(len(sigmas), len(panels), figsize=(5.6 * len(panels), 4.5 * len(sigmas) + 0.6),
                             squeeze=False)
    handles = {}
    for row, sigma in enumerate(sigmas):
        for col, (key, label, obj, title) in enumerate(panels):
            ax = axes[row][col]
            for method in methods:
                points = series(cells, method, sigma, key, obj)
                if not points:
                    continue
                colour, marker = STYLE.get(method, ("black", "o"))
                (line,) = ax.plot([p[1] for p in points], [p[2] for p in points], color=colour,
                                  marker=marker, markersize=6, linewidth=1.3, label=method)
                handles.setdefault(method, line)
                if method in ("ours-refine", "cv-sqpnp"):
                    for n, t, e in points:
                        ax.annotate(f"N={n}", (t, e), textcoords="offset points", xytext=(5, 4),
                                    fontsize=7, color=colour)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.grid(True, which="both", alpha=0.25)
            ax.set_xlabel("median wall time per fit (ms, one core)")
            ax.set_ylabel(label)
            ax.set_title(f"σ = {sigma:g} px, {title}, projector", fontsize=10)
    fig.legend([handles[m] for m in methods if m in handles], [m for m in methods if m in handles],
               loc="lower center", ncol=len(handles), fontsize=9, frameon=False)
    fig.suptitle("Error against run time: one marker per N (6 … 10000), lower-left is better",
                 fontsize=12)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def slope(points, min_n):
    xs = [math.log(n) for n, t, _ in points if n >= min_n]
    ys = [math.log(t) for n, t, _ in points if n >= min_n]
    if len(xs) < 2:
        return float("nan")
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else float("nan")


def scaling(data, path):
    cells, methods = data["cells"], [m["name"] for m in data["methods"]]
    configs = [("cloud", "projector", "non-planar points"), ("plane", "projector", "planar points")]
    fig, axes = plt.subplots(1, len(configs), figsize=(6.4 * len(configs), 4.8), squeeze=False)
    for col, (obj, camera, title) in enumerate(configs):
        ax = axes[0][col]
        for method in methods:
            points = series(cells, method, 0.5, "time_median_us", obj, camera)
            if not points:
                continue
            colour, marker = STYLE.get(method, ("black", "o"))
            ax.plot([p[0] for p in points], [p[1] for p in points], color=colour, marker=marker,
                    linewidth=1.3, label=f"{method}: slope {slope(points, 100):.2f}")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.25)
        ax.set_xlabel("N (points)")
        ax.set_ylabel("median wall time per fit (ms, one core)")
        ax.set_title(f"σ = 0.5 px, {title}, projector")
        ax.legend(fontsize=8, loc="upper left", title="log-log slope over N ≥ 100", title_fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    directory = sys.argv[1]
    with open(os.path.join(directory, "results.json"), encoding="utf-8") as f:
        data = json.load(f)
    error_vs_time(data, os.path.join(directory, "error_vs_time.png"))
    scaling(data, os.path.join(directory, "scaling.png"))


if __name__ == "__main__":
    main()
