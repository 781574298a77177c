#!/usr/bin/python3
"""Charts of kit-bench's results.csv (run by kit-bench with /usr/bin/python3, whose
python3-matplotlib Debian installs).

    charts.py RESULTS.csv OUT_DIR

speed_accuracy.png/.svg: frame time against display error, one numbered point per
method at its RMS error with a whisker up to its largest error, and the Pareto
front (no other method both faster and more accurate in RMS) drawn through them;
a ring marks the methods no other beats on time, RMS error and G-buffer bytes
together, where times within each other's frame-to-frame spread count as a tie;
left the scene with its own lights, right the most small lights measured; a third
panel gives the G-buffer layouts' bytes per pixel.
lights_scaling.png/.svg: frame time against the number of small lights for the
full-screen loop, light volumes, tiled deferred and forward shading.
ibl_speed_accuracy.png/.svg: the IBL family (stage 6's precomputed maps), one panel per
environment: precompute time against the relative error of the image against the
reflectance integral at the sampled pixels (dot the mean, bar top the largest), one
line per sweep through the lab's settings; a last panel gives stage 6's frame times.
Each chart is written when its rows are present (kit-bench --ibl-only has only the last).
"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")  # headless: files only
import matplotlib.pyplot as plt  # noqa: E402

# Errors are drawn in display steps (1/255) on a log axis; an exact match (0)
# would fall off it, so errors below this floor are drawn at it and labelled so.
ERROR_FLOOR_STEPS = 1e-3
LABS = "labs"  # the labs' default method, marked on every chart
LAYOUTS = [("reference", "RGBA32F pos+normal"), ("labs", "seed 002 (labs)"),
           ("gbuffer-lean16", "lean, RG16 normal"), ("gbuffer-lean8", "lean, RG8 normal")]
SCALING = [("labs", "full-screen loop (labs)", "black", "-"),
           ("volumes-e1024", "light volumes, eps 1/1024", "tab:blue", "-"),
           ("volumes-e256", "light volumes, eps 1/256", "tab:blue", "--"),
           ("volumes-e64", "light volumes, eps 1/64", "tab:blue", ":"),
           ("lab7-volumes", "light volumes, lab 7 (solutions)", "tab:purple", "-"),
           ("tiled-e1024", "tiled, eps 1/1024", "tab:green", "-"),
           ("tiled-e256", "tiled, eps 1/256", "tab:green", "--"),
           ("tiled-e64", "tiled, eps 1/64", "tab:green", ":"),
           ("tiled-lean16-e1024", "tiled, eps 1/1024, lean16 G-buffer", "tab:olive", "-"),
           ("tiled-ref32-e1024", "tiled, eps 1/1024, RGBA32F G-buffer", "tab:cyan", "-"),
           ("forward", "forward", "tab:red", "-")]
# The IBL family's sweeps: (label, colour, [(method, value label)]), each through the
# lab's own settings (ibl-default).
IBL = "ibl"
IBL_DEFAULT = "ibl-default"
IBL_SWEEPS = [("prefilter samples", "tab:blue",
               [("ibl-prefilter16", "16"), ("ibl-prefilter64", "64"), (IBL_DEFAULT, "256"),
                ("ibl-prefilter1024", "1024")]),
              ("BRDF table samples", "tab:green",
               [("ibl-lut32", "32"), ("ibl-lut128", "128"), (IBL_DEFAULT, "512"), ("ibl-lut2048", "2048")]),
              ("prefiltered map width", "tab:orange",
               [("ibl-size64", "64"), ("ibl-size128", "128"), (IBL_DEFAULT, "256"), ("ibl-size512", "512")]),
              ("irradiance map", "tab:red", [(IBL_DEFAULT, "irradiance.frag"), ("ibl-sh2", "SH order 2")])]
FAMILY_COLORS = {"reference": "tab:gray", "gbuffer": "tab:purple", "lighting": "tab:blue",
                 "bloom": "tab:orange", "geometry": "tab:brown"}


def read_rows(path):
    """The rows, numbers parsed: (image rows, IBL rows). An IBL row has no image comparison
    (its cells are empty), the others no IBL figures."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    image_rows, ibl_rows = [], []
    for r in rows:
        for key in ("median_ms", "min_ms", "max_ms"):
            r[key] = float(r[key])
        for key in ("lights", "bytes_per_pixel", "total_lights"):
            r[key] = int(r[key])
        if r["family"] == IBL:
            for key in r:
                if key.startswith(("max_rel_", "mean_rel_")) or key in ("precompute_ms", "irradiance_ms"):
                    r[key] = float(r[key])
            ibl_rows.append(r)
        else:
            for key in ("max_abs_ldr", "frac_over_1_255", "psnr_ldr"):
                r[key] = float(r[key])
            image_rows.append(r)
    return image_rows, ibl_rows


def steps(row):
    """RMS display error in 1/255 steps (PSNR's peak is 1.0)."""
    return max(255.0 * 10.0 ** (-row["psnr_ldr"] / 20.0), ERROR_FLOOR_STEPS)


def max_steps(row):
    return max(row["max_abs_ldr"] * 255.0, ERROR_FLOOR_STEPS)


def pareto(rows):
    """Rows no other row beats on both time and error, by increasing time."""
    front, best = [], math.inf
    for r in sorted(rows, key=lambda r: (r["median_ms"], steps(r))):
        if steps(r) < best:
            front.append(r)
            best = steps(r)
    return front


def time_tie(a, b):
    """Frame times closer than the frame-to-frame spread: one median inside the other's [min, max]."""
    return b["min_ms"] <= a["median_ms"] <= b["max_ms"] or a["min_ms"] <= b["median_ms"] <= a["max_ms"]


def dominates(a, b):
    """a beats b on (time, RMS error, G-buffer bytes): no worse on all three, better on one.
    Times that tie within the spread count as equal, so noise alone never decides."""
    tie = time_tie(a, b)
    time_no_worse = tie or a["median_ms"] < b["median_ms"]
    time_better = not tie and a["median_ms"] < b["median_ms"]
    no_worse = time_no_worse and steps(a) <= steps(b) and a["bytes_per_pixel"] <= b["bytes_per_pixel"]
    better = time_better or steps(a) < steps(b) or a["bytes_per_pixel"] < b["bytes_per_pixel"]
    return no_worse and better


def front_3d(rows):
    """Methods no other method dominates on (time within noise, RMS error, bytes per pixel)."""
    return [r for r in rows if not any(dominates(o, r) for o in rows if o is not r)]


def scatter(ax, rows, title):
    if not rows:
        ax.set_visible(False)
        return
    rows = sorted(rows, key=lambda r: r["median_ms"])
    for i, r in enumerate(rows, 1):
        color = FAMILY_COLORS.get(r["family"], "black")
        marker = "*" if r["method"] == LABS else "o"
        ax.plot([r["median_ms"]] * 2, [steps(r), max_steps(r)], color=color, linewidth=0.8, alpha=0.6, zorder=2)
        ax.scatter(r["median_ms"], max_steps(r), color=color, marker="_", s=40, zorder=3)
        label = "%d  %s" % (i, r["method"])
        if r["family"] in ("gbuffer", "reference"):
            label += " (%d B/px)" % r["bytes_per_pixel"]
        label += ": %.3g ms, max %.3g/255" % (r["median_ms"], r["max_abs_ldr"] * 255.0)
        ax.scatter(r["median_ms"], steps(r), color=color, marker=marker, s=160 if marker == "*" else 30, zorder=4,
                   label=label)
        ax.annotate(str(i), (r["median_ms"], steps(r)), fontsize=7, xytext=(3, -9), textcoords="offset points")
    front = pareto(rows)
    ax.step([r["median_ms"] for r in front], [steps(r) for r in front], where="post", color="tab:red",
            linewidth=1, label="Pareto front (median time, RMS error)", zorder=1)
    ringed = front_3d(rows)
    ax.scatter([r["median_ms"] for r in ringed], [steps(r) for r in ringed], s=260, facecolors="none",
               edgecolors="tab:red", linewidths=0.8, zorder=5,
               label="front on time (ties within the spread), RMS error and G-buffer bytes")
    ax.axhline(1.0, color="gray", linestyle="--", linewidth=0.8, label="1/255 (one display step)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("frame time, median (ms, wall clock, llvmpipe)")
    ax.set_ylabel("display error, 1/255 steps: dot RMS, bar top largest (floor %.2g)" % ERROR_FLOOR_STEPS)
    ax.set_title(title, fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2, frameon=False)


def bytes_panel(ax, rows):
    present = [(m, label) for m, label in LAYOUTS if any(r["method"] == m for r in rows)]
    if not present:
        ax.set_visible(False)
        return
    values = [next(r for r in rows if r["method"] == m) for m, _ in present]
    bars = ax.bar([label for _, label in present], [r["bytes_per_pixel"] for r in values],
                  color=["tab:gray", "tab:purple", "tab:green", "tab:olive"][:len(values)])
    for bar, r in zip(bars, values):
        ax.annotate("%d B\nmax %.2g/255" % (r["bytes_per_pixel"], r["max_abs_ldr"] * 255.0),
                    (bar.get_x() + bar.get_width() / 2, bar.get_height()), ha="center", va="bottom", fontsize=7)
    ax.set_ylabel("G-buffer bytes per pixel")
    ax.set_title("G-buffer layouts", fontsize=9)
    ax.tick_params(axis="x", labelrotation=20, labelsize=7)
    ax.set_ylim(0, max(r["bytes_per_pixel"] for r in values) * 1.35)


def speed_accuracy(rows, out_dir):
    # The main scene's rows only: the crowd configuration (issue 13) has its own scene.
    main_scene = rows[0]["scene"] if rows else ""
    scene_rows = [r for r in rows if r["lights"] == 0 and r["scene"] == main_scene]
    most = max((r["lights"] for r in rows), default=0)
    many_rows = [r for r in rows if r["lights"] == most and most > 0]
    fig, axes = plt.subplots(1, 3, figsize=(20, 10), gridspec_kw={"width_ratios": [3, 3, 1.3]})
    size = scene_rows[0]["size"] if scene_rows else ""
    scatter(axes[0], scene_rows, "scene's own lights (%s)" % size)
    if many_rows:
        scatter(axes[1], many_rows, "%d small lights added (%d lights, %s)" %
                (most, many_rows[0]["total_lights"], many_rows[0]["size"]))
    else:
        axes[1].set_visible(False)
    bytes_panel(axes[2], scene_rows)
    fig.suptitle("kit-bench: speed against accuracy (error against the %s reference; * = the labs' method)" %
                 "/".join(sorted({r["reference"] for r in rows})), fontsize=10)
    fig.tight_layout()
    for ext in ("png", "svg"):
        fig.savefig(os.path.join(out_dir, "speed_accuracy." + ext), dpi=110)
    plt.close(fig)


def lights_scaling(rows, out_dir):
    fig, ax = plt.subplots(figsize=(8, 5.5))
    for method, label, color, style in SCALING:
        points = sorted((r["lights"], r["median_ms"]) for r in rows if r["method"] == method and r["lights"] > 0)
        if points:
            ax.plot([p[0] for p in points], [p[1] for p in points], color=color, linestyle=style, marker="o",
                    markersize=4, label=label)
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("small lights added to the scene")
    ax.set_ylabel("frame time, median (ms, wall clock, llvmpipe)")
    sizes = sorted({r["size"] for r in rows if r["lights"] > 0})
    ax.set_title("kit-bench: frame time against light count (%s)" % ", ".join(sizes), fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    for ext in ("png", "svg"):
        fig.savefig(os.path.join(out_dir, "lights_scaling." + ext), dpi=110)
    plt.close(fig)


def ibl_environments(rows):
    return [key[len("max_rel_"):] for key in rows[0] if key.startswith("max_rel_")]


def ibl_panel(ax, rows, environment):
    by_method = {r["method"]: r for r in rows}
    for label, color, points in IBL_SWEEPS:
        present = [(by_method[m], value) for m, value in points if m in by_method]
        if not present:
            continue
        xs = [r["precompute_ms"] for r, _ in present]
        ax.plot(xs, [r["mean_rel_" + environment] for r, _ in present], color=color, marker="o", markersize=4,
                label=label, zorder=3)
        for r, value in present:
            if r["method"] != IBL_DEFAULT:  # the lab's point is named once, in the legend
                ax.annotate(value, (r["precompute_ms"], r["mean_rel_" + environment]), fontsize=7, color=color,
                            xytext=(4, 3), textcoords="offset points")
            ax.plot([r["precompute_ms"]] * 2, [r["mean_rel_" + environment], r["max_rel_" + environment]], color=color,
                    linewidth=0.8, alpha=0.6, zorder=2)
            ax.scatter(r["precompute_ms"], r["max_rel_" + environment], color=color, marker="_", s=40, zorder=3)
    if IBL_DEFAULT in by_method:
        r = by_method[IBL_DEFAULT]
        ax.scatter(r["precompute_ms"], r["mean_rel_" + environment], marker="*", s=160, color="black", zorder=4,
                   label="the lab's settings (ibl-default)")
    first = rows[0]
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("precompute time of the three maps, median (ms, wall clock, llvmpipe)")
    ax.set_ylabel("relative error against the integral: dot mean, bar top largest")
    ax.set_title("under '%s': %s px of the %s scene (%s), integral of %s samples a pixel" %
                 (environment, first["ibl_pixels"], first["scene"], first["size"], first["integral_samples"]),
                 fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=3, frameon=False)


def ibl_frame_panel(ax, rows):
    rows = sorted(rows, key=lambda r: r["median_ms"])
    names = [r["method"] for r in rows]
    medians = [r["median_ms"] for r in rows]
    spread = [[r["median_ms"] - r["min_ms"] for r in rows], [r["max_ms"] - r["median_ms"] for r in rows]]
    ax.barh(names, medians, xerr=spread, color="tab:gray", error_kw={"linewidth": 0.8})
    ax.tick_params(axis="y", labelsize=7)
    ax.set_xlabel("stage 6 frame time (ms): median, min-max")
    ax.set_title("frame time (%s)" % rows[0]["size"], fontsize=9)


def ibl_speed_accuracy(rows, out_dir):
    environments = ibl_environments(rows)
    fig, axes = plt.subplots(1, len(environments) + 1, figsize=(7 * len(environments) + 5, 6.5),
                             gridspec_kw={"width_ratios": [3] * len(environments) + [1.6]})
    for ax, environment in zip(axes, environments):
        ibl_panel(ax, rows, environment)
    ibl_frame_panel(axes[-1], rows)
    lab = ", ".join("%s %s" % (label, dict(points)[IBL_DEFAULT]) for label, _, points in IBL_SWEEPS)
    fig.suptitle("kit-bench, image-based lighting: precompute time against error (stage 6 without the scene's lights; "
                 "error relative to max(integral, 0.02))\n* the lab's settings: %s" % lab, fontsize=10)
    fig.tight_layout()
    for ext in ("png", "svg"):
        fig.savefig(os.path.join(out_dir, "ibl_speed_accuracy." + ext), dpi=110, bbox_inches="tight")
    plt.close(fig)


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: charts.py RESULTS.csv OUT_DIR")
    rows, ibl_rows = read_rows(sys.argv[1])
    if not rows and not ibl_rows:
        sys.exit("charts.py: %s holds no rows" % sys.argv[1])
    if rows:
        speed_accuracy(rows, sys.argv[2])
        lights_scaling(rows, sys.argv[2])
    if ibl_rows:
        ibl_speed_accuracy(ibl_rows, sys.argv[2])


if __name__ == "__main__":
    main()
