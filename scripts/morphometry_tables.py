#!/usr/bin/python3
"""The measured tables of docs/morphometry-tables.md: every shipped growth example's morphometry
beside the shipped references, the organ parameter sets against the examples they start from
(over five seeds), and what each method's asymmetry, angle and tortuosity controls move.

    /usr/bin/python3 scripts/morphometry_tables.py [BUILD_DIR] [OUT_MD]

Runs `angiosynth generate` and `angiosynth stats --compare` on copies of examples/ in a
temporary directory; about three minutes on two cores."""
import json
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BUILD = Path(sys.argv[1] if len(sys.argv) > 1 else ROOT / "build").resolve()
OUT = Path(sys.argv[2] if len(sys.argv) > 2 else ROOT / "docs/morphometry-tables.md")
PROGRAM = BUILD / "angiosynth"
REFERENCES = ["kassab1993_pig_coronary_rca", "kassab1993_pig_coronary_lad", "murray_exponent_bands", "cassot2010_human_cortex_arterioles"]
SKIP = {"dataset_artery_vein.toml"}  # a dataset spec, not a tree
SEEDS = [1, 2, 3, 4, 5]


def set_key(text, table, key, value):
    """`key = value` in [table] (or the first [[table]]), replacing the key or adding it."""
    header = re.search(r"^\[\[?" + re.escape(table) + r"\]\]?[^\n]*\n", text, flags=re.M)
    if not header:
        return text.rstrip("\n") + f"\n\n[{table}]\n{key} = {value}\n"
    start = header.end()
    nxt = re.search(r"^\[", text[start:], flags=re.M)
    end = start + nxt.start() if nxt else len(text)
    body = text[start:end]
    line = re.compile(r"^" + re.escape(key) + r"\s*=.*$", flags=re.M)
    body = line.sub(f"{key} = {value}", body) if line.search(body) else f"{key} = {value}\n" + body
    return text[:start] + body + text[end:]


class Runner:
    def __init__(self, work):
        self.work = work
        shutil.copytree(ROOT / "examples", work / "examples")
        shutil.copytree(ROOT / "demand_maps", work / "demand_maps")
        self.count = 0

    def measure(self, example, edits=(), seed=None, references=REFERENCES):
        """stats.json and comparison.json of `example` (a path under examples/) with edits."""
        self.count += 1
        src = self.work / "examples" / example
        text = src.read_text()
        for table, key, value in edits:
            text = set_key(text, table, key, value)
        param = src.parent / f"_run{self.count}_{src.name}"
        param.write_text(text)
        out = self.work / f"out{self.count}"
        cmd = [str(PROGRAM), "generate", str(param), "--out", str(out), "--no-image", "--no-profiles", "--quiet"]
        if seed is not None:
            cmd += ["--seed", str(seed)]
        subprocess.run(cmd, check=True)
        stats = self.work / f"stats{self.count}"
        subprocess.run([str(PROGRAM), "stats", str(out), "--out", str(stats), "--quiet", "--compare", *references], check=True)
        s = json.loads((stats / "stats.json").read_text())["groups"][0]
        c = {x["reference"]: x for x in json.loads((stats / "comparison.json").read_text())["comparisons"]}
        return s, c


def fmt(v, digits=3):
    return "–" if v is None else f"{v:.{digits}g}"


def summary(s, key, what="median"):
    x = s["summaries"].get(key)
    return None if not x else x[what]


def murray_band(c, lower):
    for r in c["murray_exponent_bands"]["statistics"]:
        if r["band_mm"][0] == lower:
            return r["tree"]
    return None


def examples_table(run):
    rows = []
    names = sorted(p.name for p in (ROOT / "examples").glob("*.toml") if p.name not in SKIP and "method" in p.read_text())
    for name in names:
        if "\nmethod" not in (ROOT / "examples" / name).read_text() or name.startswith(("dataset", "large")):
            continue
        s, c = run.measure(name)
        h = s["horton_ratios_by_diameter"]
        rows.append(
            f"| {name[:-5]} | {s['terminals']} | {fmt(h['branching'])} | {fmt(h['diameter'])} | {fmt(h['length'])} | "
            f"{fmt(murray_band(c, 0.0))} / {fmt(murray_band(c, 0.1))} / {fmt(murray_band(c, 1))} | {fmt(summary(s, 'area_ratio', 'mean'))} | "
            f"{fmt(summary(s, 'daughter_area_ratio', 'mean'))} | {fmt(summary(s, 'angle_between_deg'))} | {fmt(summary(s, 'distance_metric'))} | "
            + " | ".join(fmt(c[r]["overall_distance"], 2) for r in REFERENCES)
            + " |"
        )
    # The references' own values, as the comparison reads them.
    ref = {r: {x["statistic"] + str(x["band_mm"][0]): x for x in c[r]["statistics"]} for r in REFERENCES}
    rca, lad, mb, cas = (ref[r] for r in REFERENCES)
    refrows = [
        f"| *Kassab et al. 1993, pig RCA (orders 5–11)* | | {fmt(rca['horton_branching0.0']['reference'])} | "
        f"{fmt(rca['horton_diameter0.0']['reference'])} | {fmt(rca['horton_length0.0']['reference'])} | | | | | | 0 | | | |",
        f"| *Kassab et al. 1993, pig LAD (orders 5–11)* | | {fmt(lad['horton_branching0.0']['reference'])} | "
        f"{fmt(lad['horton_diameter0.0']['reference'])} | {fmt(lad['horton_length0.0']['reference'])} | | | | | | | 0 | | |",
        f"| *Kassab & Fung 1995; Huo & Kassab 2012* | | | | | {fmt(mb['murray_exponent0.0']['reference'])} / "
        f"{fmt(mb['murray_exponent0.1']['reference'])} / {fmt(mb['murray_exponent1.0']['reference'])} | | | | | | | 0 | |",
        f"| *Cassot et al. 2010, human cortical arterioles* | | | | | | {fmt(cas['area_ratio0.0']['reference'])} | "
        f"{fmt(cas['daughter_area_ratio0.0']['reference'])} | | | | | | 0 |",
    ]
    head = (
        "| example | terminals | R_B | R_D | R_L | Murray γ < 0.1 / 0.1–1 / > 1 mm | area ratio | daughters' area ratio | angle between (°) | "
        "distance metric | RCA | LAD | Murray bands | cortex |\n|" + "---|" * 14
    )
    return head + "\n" + "\n".join(refrows + rows)


def organ_table(run, title, default, tuned, references, statistics):
    lines = [f"**{title}** (mean over seeds {SEEDS[0]}–{SEEDS[-1]}; distance in [0, 1], 0 = alike)\n",
             "| statistic | reference | default: value | default: distance | tuned: value | tuned: distance | closer |", "|---|---|---|---|---|---|---|"]
    results = {}
    for label, example in (("default", default), ("tuned", tuned)):
        per = {}
        overall = []
        for seed in SEEDS:
            _, c = run.measure(example, seed=seed, references=references)
            for r in references:
                overall.append(c[r]["overall_distance"])
                for x in c[r]["statistics"]:
                    key = (r, x["statistic"], x["band_mm"][0])
                    per.setdefault(key, []).append((x["tree"], x["distance"], x["reference"], x["band_mm"]))
        results[label] = (per, statistics_mean(overall))
    closer_all = True
    bars = []
    for key in results["default"][0]:
        if statistics and key[1] not in statistics:
            continue
        d = results["default"][0][key]
        t = results["tuned"][0][key]
        dv, dd = mean([v[0] for v in d]), mean([v[1] for v in d])
        tv, td = mean([v[0] for v in t]), mean([v[1] for v in t])
        closer = td <= dd + 5e-4
        closer_all &= closer
        band = f" ({band_text(d[0][3])} mm)" if key[1] == "murray_exponent" else ""
        lines.append(f"| {key[1]}{band} | {fmt(d[0][2])} | {fmt(dv)} | {dd:.3f} | {fmt(tv)} | {td:.3f} | {'equal' if abs(td - dd) <= 5e-4 else 'yes' if td < dd else 'no'} |")
        bars.append((f"{key[1]}{band}", dd, td))
    lines.append(
        f"| **overall** | | | {results['default'][1]:.3f} | | {results['tuned'][1]:.3f} | "
        f"{'yes' if results['tuned'][1] < results['default'][1] else 'no'} |"
    )
    return "\n".join(lines), closer_all, bars


def band_text(band):
    lo, hi = band
    return f"> {lo:g}" if hi == "inf" else f"{lo:g}–{hi:g}" if lo > 0 else f"< {hi:g}"


def figure(coronary, cortex, path):
    """Bars of each statistic's distance to its reference, example against organ set."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2), gridspec_kw={"width_ratios": [len(coronary), max(len(cortex), 3)]})
    for ax, bars, title in ((axes[0], coronary, "pig coronary arteries (Kassab et al. 1993; Murray bands)"),
                            (axes[1], cortex, "human cortical arterioles\n(Cassot et al. 2010)")):
        x = range(len(bars))
        ax.bar([i - 0.2 for i in x], [b[1] for b in bars], 0.4, label="shipped example", color="#999999")
        ax.bar([i + 0.2 for i in x], [b[2] for b in bars], 0.4, label="organ set", color="#2b4c9a")
        ax.set_xticks(list(x))
        ax.set_xticklabels([b[0].replace("murray_exponent", "Murray γ").replace("horton_", "Horton ") for b in bars], rotation=25, ha="right", fontsize=8)
        ax.set_ylim(0, 1)
        ax.set_title(title, fontsize=10)
        ax.set_ylabel("distance to the reference (0 = alike)")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)


def mean(v):
    v = [x for x in v if x is not None]
    return sum(v) / len(v) if v else None


def statistics_mean(v):
    return mean(v)


def sweep(run, example, table, key, values, columns, extra=()):
    head = f"| {key} | " + " | ".join(c[0] for c in columns) + " |\n|" + "---|" * (len(columns) + 1)
    rows = []
    for v in values:
        s, _ = run.measure(example, edits=[*extra, (table, key, v)], references=["murray_exponent_bands"])
        rows.append(f"| {v} | " + " | ".join(fmt(c[1](s)) for c in columns) + " |")
    return head + "\n" + "\n".join(rows)


def main():
    with tempfile.TemporaryDirectory(prefix="angiosynth_morphometry_") as tmp:
        run = Runner(Path(tmp))
        out = ["<!-- Generated by scripts/morphometry_tables.py; do not edit by hand. -->", "# Morphometry tables", ""]
        out += ["## Shipped examples beside the references", "",
                "Horton's ratios by diameter-defined Strahler order (as Kassab et al. 1993 order casts); Murray's exponent: the median per band of "
                "parent radius; area ratios: means over bifurcations; angle and distance metric: medians. The last four columns: `stats --compare`'s "
                "overall distance to each shipped reference (mean over its statistics of the KS distance; 0 = alike, 1 = apart).", "",
                examples_table(run), ""]
        out += ["## Parameter sets per organ", "",
                "Each set starts from a shipped example and changes what the text of its file says; both are grown with five seeds and compared "
                "statistic by statistic (`stats --compare`).", ""]
        coronary, ok1, bars1 = organ_table(run, "Pig coronary arteries (examples/morphometry/coronary_vascusynth.toml against vascusynth_like.toml)",
                                    "vascusynth_like.toml", "morphometry/coronary_vascusynth.toml",
                                    ["kassab1993_pig_coronary_rca", "murray_exponent_bands"], None)
        cortex, ok2, bars2 = organ_table(run, "Human cortical arterioles (examples/morphometry/cortex_arterioles_grammar.toml against lsystem_grammar_3d.toml)",
                                  "lsystem_grammar_3d.toml", "morphometry/cortex_arterioles_grammar.toml", ["cassot2010_human_cortex_arterioles"], None)
        figure(bars1, bars2, ROOT / "docs/gallery/morphometry_organ_sets.png")
        out += ["![Distance to the reference per statistic: each shipped example against its organ set](gallery/morphometry_organ_sets.png)", "",
                coronary, "", cortex, ""]
        out += ["## What each control moves", "",
                "One setting swept on a shipped example, the rest as shipped; medians over the tree's vessels or bifurcations "
                "(`stats`). Asymmetry: r_small / r_large of the daughters.", ""]
        asym = [("asymmetry", lambda s: summary(s, "asymmetry")), ("daughters' area ratio (mean)", lambda s: summary(s, "daughter_area_ratio", "mean")),
                ("angle between (°)", lambda s: summary(s, "angle_between_deg"))]
        angles = [("angle large (°)", lambda s: summary(s, "angle_large_deg")), ("angle small (°)", lambda s: summary(s, "angle_small_deg")),
                  ("angle between (°)", lambda s: summary(s, "angle_between_deg")), ("asymmetry", lambda s: summary(s, "asymmetry"))]
        out += ["**L-system grammar** (lsystem_grammar_3d): `[tree] diameter_sd`, the spread of the first daughter's diameter", "",
                sweep(run, "lsystem_grammar_3d.toml", "tree", "diameter_sd", ["0", "0.1", "0.2", "0.3"], asym), ""]
        out += ["**L-system grammar** (lsystem_grammar_3d): `[tree] angles = \"fixed\"`, `branch_angle`", "",
                sweep(run, "lsystem_grammar_3d.toml", "tree", "branch_angle", ["30", "45", "60"], angles, extra=[("tree", "angles", '"fixed"')]), ""]
        out += ["**Space colonisation** (colonisation_fig5_2d): `[physics] murray_exponent` κ, which also sets the branching angles", "",
                sweep(run, "colonisation_fig5_2d.toml", "physics", "murray_exponent", ["2.2", "2.55", "3.0", "3.5"], angles), ""]
        out += ["**DCCO** (dcco_pdf_uniform_2d): `[[stage]] symmetry` δ, the least r_small / r_large a bifurcation may have", "",
                sweep(run, "dcco_pdf_uniform_2d.toml", "stage", "symmetry", ["0", "0.3", "0.6"], asym), ""]
        out += ["**CCO** (cco_sphere_3d, 1000 terminals): `[physics] murray_exponent` γ; the angles follow from the optimised bifurcations", "",
                sweep(run, "cco_sphere_3d.toml", "physics", "murray_exponent", ["2.333", "2.7", "3"], angles, extra=[("tree", "terminals", "1000")]), ""]
        tort = [("distance metric", lambda s: summary(s, "distance_metric")), ("sum of angles (rad/mm)", lambda s: summary(s, "sum_of_angles_per_mm")),
                ("inflections", lambda s: summary(s, "inflections", "mean"))]
        out += ["**Curves** (cco_sphere_curved_3d): `[curves] tortuosity`, the distance metric each vessel is drawn to", "",
                sweep(run, "cco_sphere_curved_3d.toml", "curves", "tortuosity", ["1.1", "1.2", "1.4"], tort), ""]
        out += ["**Curves** (cco_sphere_curved_3d): `[curves] wavelength_radii`, which sets the inflections per vessel", "",
                sweep(run, "cco_sphere_curved_3d.toml", "curves", "wavelength_radii", ["20", "40", "80"], tort), ""]
        OUT.write_text("\n".join(out) + "\n")
        print(f"wrote {OUT}; coronary set closer on every statistic: {ok1}; cortex set: {ok2}")


if __name__ == "__main__":
    main()
