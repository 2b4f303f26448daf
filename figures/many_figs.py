"""Figures and checks of the many-particle validation piece (scripts/validate.d/40-many.sh).

Reads the --out directories of the five shipped scenarios, the chute's wet and dry
(global.csv, summary.json and the VTK frames, ASCII or binary), and writes
docs/figures/many_cradle.png, many_settling.png, many_agglomeration.png, many_rough_base.png
and many_chute.png. Checks, each printed and failing the script:
  cradle        x momentum conserved (no walls, no gravity: only pair forces, equal and
                opposite) to 1e-9 of the striker's; the last sphere leaves with more than
                half the striker's speed and faster than every other sphere;
  settling      energy closure |balance_error| < 2e-3 of the work of all forces (O(dt^2)
                Verlet error plus the film forces' jumps at h = delta and h_min); the bed is
                at rest (kinetic < 1e-4 of the potential energy released); every sphere ends
                in contact or bridged (contacts + bridges >= number of spheres); the floor's
                links (particles_links) carry the bed's weight to 3 % over the last eight
                frames (the bed rings on its soft contacts: 0.92-1.07 frame by frame);
  agglomeration the number of liquid bridges grows tenfold, the mean agglomerate size grows
                tenfold, the agglomerate count first rises above its start (clusters form)
                and then falls (they merge); closure < 2e-2 of the work (larger steps: 1/20
                of the contact time); the VTK frames' agglomerate labels agree with the
                CSV rows of their steps (count and mean size), and their bridges and
                contacts per sphere add up to twice the rows'.
  rough base    the 64 fixed spheres read from examples/scenarios/rough_base.csv stay where
                the file put them, bit for bit, and at rest in every frame (marked fixed);
                no free sphere reaches the floor (the floor does no work: the base holds the
                grains); closure < 2e-3 of the work; at rest at the end (kinetic < 1e-4 of
                the potential energy released).
  chute         wet grains on the rough base under gravity tilted by 30 deg come to rest
                (mean downslope speed < 1e-3 m/s from 0.1 s on), dry ones keep flowing
                (mean > 3 cm/s, every frame from 0.1 s on within 25 % of it); closure
                < 2e-3 of the work in both; the largest speed within the speed bound of the
                step in both. Writes many_chute.png too.
Usage: /usr/bin/python3 figures/many_figs.py --dir out/validate/many
"""
import argparse
import configparser
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "tools"))
from common import FIGURES, ROOT, np, plt  # noqa: E402
from wetdem_vtk import read_vtk  # noqa: E402

failures = []


def check(ok, text):
    print(f"  [{'ok' if ok else 'FAIL'}] {text}")
    if not ok:
        failures.append(text)


def save_and_finish(fig, name):
    """Writes the figure to docs/figures/NAME (tight layout, 120 dpi), then exits 1 when a
    check failed."""
    fig.tight_layout()
    os.makedirs(FIGURES, exist_ok=True)
    path = os.path.join(FIGURES, name)
    fig.savefig(path, dpi=120)
    print(f"  wrote {os.path.relpath(path)}")
    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)


def read_global(path):
    """global.csv as {column: array}, the columns by name without their unit ("time [s]":
    "time")."""
    with open(path) as f:
        lines = [ln.strip() for ln in f if not ln.startswith("#") and ln.strip()]
    names = [h.split(" [")[0] for h in lines[0].split(",")]
    rows = np.array([[float(x) for x in ln.split(",")] for ln in lines[1:]])
    return {n: rows[:, k] for k, n in enumerate(names)}


def energy_panel(ax, g):
    """Kinetic, dissipated and released potential energy against time (global.csv columns),
    on a log scale (values below 1e-14 J drawn at it)."""
    t = g["time"] * 1e3
    ax.semilogy(t, np.maximum(g["kinetic"], 1e-14), label="kinetic")
    ax.semilogy(t, g["dissipated"].clip(1e-14), label="dissipated")
    ax.semilogy(t, (g["potential"][0] - g["potential"]).clip(1e-14), label="potential released")
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("energy [J]")
    ax.legend(fontsize=8)


def frames(run_dir):
    """(time, positions, velocities) of each frame of a run, in the order of its series."""
    series = json.load(open(os.path.join(run_dir, "particles.vtk.series")))
    fr = [read_vtk(os.path.join(run_dir, e["name"])) for e in series["files"]]
    return [(f["TIME"][0], f["POINTS"], f["velocity"]) for f in fr]


def cradle(run_dir):
    print("Stokes cradle")
    fr = frames(run_dir)
    t = np.array([f[0] for f in fr]) * 1e3
    vx = np.array([f[2][:, 0] for f in fr])
    v0 = vx[0, 0]
    drift = np.max(np.abs(vx.sum(axis=1) - vx[0].sum()))
    check(drift < 1e-9 * v0, f"x momentum conserved: largest change {drift / v0:.2e} of the striker's")
    last = vx[-1]
    check(last[-1] > 0.5 * v0 and last[-1] == last.max(),
          f"the last sphere leaves at {last[-1]:.3f} m/s = {last[-1] / v0:.2f} v0, the others at "
          f"{', '.join(f'{v:.3f}' for v in last[:-1])} m/s")
    fig, ax = plt.subplots(figsize=(6, 3.6))
    for k in range(vx.shape[1]):
        ax.plot(t, vx[:, k], marker=".", label=f"sphere {k + 1}")
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("velocity $v_x$ [m/s]")
    ax.set_title("Stokes cradle: five coated steel spheres, 0.1 Pa s oil")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, "many_cradle.png"), dpi=120)


def settling(run_dir):
    print("wet granular settling")
    g = read_global(os.path.join(run_dir, "global.csv"))
    s = json.load(open(os.path.join(run_dir, "summary.json")))
    e = s["energy_J"]
    released = g["potential"][0] - e["potential"]
    check(abs(e["balance_error"]) < 2e-3 * abs(e["work_total"]),
          f"energy closure {abs(e['balance_error']) / abs(e['work_total']):.2e} of the work")
    check(e["kinetic"] < 1e-4 * released,
          f"at rest: kinetic {e['kinetic']:.2e} J against {released:.2e} J released")
    check(s["contacts"] + s["bridges"] >= s["particles"],
          f"{s['contacts']} contacts and {s['bridges']} bridges hold {s['particles']} spheres")
    # the force network (particles_links): the floor carries the bed's weight. The bed still
    # rings on its soft contacts (the floor's force swings by about 7 % between frames about
    # 3 ms apart), so the force is averaged over the last eight frames
    series = json.load(open(os.path.join(run_dir, "particles.vtk.series")))
    last = len(series["files"]) - 1
    ini = configparser.ConfigParser(inline_comment_prefixes=(";",))
    ini.read(os.path.join(ROOT, "examples", "scenarios", "many_settling.ini"))
    density = float(ini["material.wetglass"]["density"])
    ratios = []
    for k in range(last - 7, last + 1):
        p = read_vtk(os.path.join(run_dir, series["files"][k]["name"]))
        lk = read_vtk(os.path.join(run_dir, f"particles_links_{k:06d}.vtk"))
        weight = (density * 4 / 3 * np.pi * p["radius"] ** 3).sum() * 9.81
        ratios.append(lk["force"][lk["j"] < 0, 2].sum() / weight)
    check(abs(np.mean(ratios) - 1) < 0.03,
          f"the floor carries {np.mean(ratios):.3f} of the weight (last eight frames: "
          f"{min(ratios):.3f} to {max(ratios):.3f})")
    t = g["time"] * 1e3
    fig, (a, b, c) = plt.subplots(1, 3, figsize=(13, 3.8))
    energy_panel(a, g)
    for name in [c for c in g if c.startswith("work_")]:
        b.plot(t, -g[name] * 1e6, label=name[5:])
    b.set_xlabel("time [ms]")
    b.set_ylabel("energy taken by the model [uJ]")
    b.legend(fontsize=8)
    # the last frame's compressive links in a slab 2 mm thick across y, seen along y: line
    # width and shade by the normal force (a force chain is a path of thick lines)
    y = lk["POINTS"][:, 1].reshape(-1, 2).mean(axis=1)
    mid = 0.5 * (p["POINTS"][:, 1].min() + p["POINTS"][:, 1].max())
    fn = lk["force_normal"]
    sel = (np.abs(y - mid) < 1e-3) & (fn > 0)
    ends = lk["POINTS"].reshape(-1, 2, 3)[sel][:, :, [0, 2]] * 1e3
    from matplotlib.collections import LineCollection
    scale = fn[sel] / np.percentile(fn[fn > 0], 99)
    c.add_collection(LineCollection(ends, linewidths=0.3 + 3 * np.clip(scale, 0, 1),
                                    colors=plt.get_cmap("viridis_r")(np.clip(scale, 0, 1))))
    c.set_xlim(ends[:, :, 0].min(), ends[:, :, 0].max())
    c.set_ylim(0, ends[:, :, 1].max() + 0.5)
    c.set_aspect("equal")
    c.set_xlabel("x [mm]")
    c.set_ylabel("z [mm]")
    c.set_title(f"compressive links, slab |y - {mid * 1e3:.0f} mm| < 1 mm: width ~ force",
                fontsize=9)
    fig.suptitle("Wet settling of 2000 spheres: energy budget per model and the force network")
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, "many_settling.png"), dpi=120)


def agglomeration(run_dir):
    print("agglomeration in a periodic box")
    g = read_global(os.path.join(run_dir, "global.csv"))
    e = json.load(open(os.path.join(run_dir, "summary.json")))["energy_J"]
    n, size, br = g["agglomerates"], g["mean_agglomerate_size"], g["bridges"]
    check(br[-1] > 10 * max(br[0], 1), f"bridges {br[0]:.0f} -> {br[-1]:.0f}")
    check(size[-1] > 10 * max(size[0], 1), f"mean agglomerate size {size[0]:.3g} -> {size[-1]:.3g}")
    check(n.max() > n[0] and n[-1] < n.max(),
          f"agglomerates {n[0]:.0f} at the start, {n.max():.0f} at most, {n[-1]:.0f} at the end")
    check(abs(e["balance_error"]) < 2e-2 * abs(e["work_total"]),
          f"energy closure {abs(e['balance_error']) / abs(e['work_total']):.2e} of the work")
    # each frame's agglomerate labels are those of the CSV row of its step: as many labels,
    # 1..A, as agglomerates, each of >= 2 spheres, of the row's mean size (the CSV gives time
    # and size to 9 and 6 significant digits, the frame its time exactly); its spheres' bridges
    # and contacts add up to twice the row's (no walls: each link has two ends)
    series = json.load(open(os.path.join(run_dir, "particles.vtk.series")))
    matched = 0
    for entry in series["files"]:
        f = read_vtk(os.path.join(run_dir, entry["name"]))
        row = np.flatnonzero(np.abs(g["time"] - f["TIME"][0]) <= 1e-8 * f["TIME"][0])
        if len(row) == 0:
            continue
        matched += 1
        labels = f["agglomerate"]
        sizes = np.bincount(labels)[1:]
        r = row[0]
        a_count = g["agglomerates"][r]
        if not (len(sizes) == a_count and (sizes >= 2).all() and
                f["bridges"].sum() == 2 * g["bridges"][r] and
                f["contacts"].sum() == 2 * g["contacts"][r] and
                (a_count == 0 or
                 abs(sizes.mean() - g["mean_agglomerate_size"][r]) <= 1e-5 * sizes.mean())):
            break
    else:
        matched = -matched
    check(matched < 0, f"the {abs(matched)} frames at CSV rows: their labels give the rows' "
          "agglomerates and mean sizes, their bridges and contacts twice the rows'")
    # a frame while the agglomerates merge (about 15 of them; at the end one spans the box)
    snaps = [read_vtk(os.path.join(run_dir, e["name"])) for e in series["files"]]
    snap = min(snaps, key=lambda f: abs(int(f["agglomerate"].max()) - 15))
    t = g["time"] * 1e3
    fig, (a, b, s) = plt.subplots(1, 3, figsize=(13, 3.8))
    a.semilogy(t, g["kinetic"])
    a.set_xlabel("time [ms]")
    a.set_ylabel("kinetic energy [J]")
    b.plot(t, n, label="agglomerates")
    b.set_xlabel("time [ms]")
    b.set_ylabel("number of agglomerates")
    c = b.twinx()
    c.plot(t, size, color="C1", label="mean size")
    c.set_ylabel("mean agglomerate size [spheres]", color="C1")
    # that frame seen along z, each agglomerate in a colour of its own (tab20 without its
    # greys), single spheres white (ParaView: colour the Glyph by the point array "agglomerate")
    pos, lab, rad = snap["POINTS"] * 1e3, snap["agglomerate"], snap["radius"] * 1e3
    order = np.argsort(pos[:, 2])  # the nearer spheres drawn last
    palette = np.array([plt.get_cmap("tab20")(i) for i in range(20) if i not in (14, 15)])
    colours = palette[(lab[order] - 1) % len(palette)]
    colours[lab[order] == 0] = (1.0, 1.0, 1.0, 1.0)
    for k, c_k in zip(order, colours):
        s.add_patch(plt.Circle(pos[k, :2], rad[k], facecolor=c_k, edgecolor="k", lw=0.3))
    s.set_xlim(pos[:, 0].min() - 0.6, pos[:, 0].max() + 0.6)
    s.set_ylim(pos[:, 1].min() - 0.6, pos[:, 1].max() + 0.6)
    s.set_aspect("equal")
    s.set_xlabel("x [mm]")
    s.set_ylabel("y [mm]")
    s.set_title(f"t = {snap['TIME'][0] * 1e3:.0f} ms: {lab.max()} agglomerates, "
                f"{(lab == 0).sum()} single spheres (white)", fontsize=9)
    fig.suptitle("400 wet spheres in a periodic box")
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, "many_agglomeration.png"), dpi=120)


def rough_base(run_dir):
    print("wet spheres settling onto a rough base of fixed spheres")
    with open(os.path.join(ROOT, "examples", "scenarios", "rough_base.csv")) as f:
        rows = [ln for ln in f if not ln.startswith("#") and ln.strip()][1:]
    base = np.array([[float(x) for x in ln.split(",")] for ln in rows])
    nb = len(base)
    series = json.load(open(os.path.join(run_dir, "particles.vtk.series")))
    fr = [read_vtk(os.path.join(run_dir, e["name"])) for e in series["files"]]
    moved = max(np.abs(f["POINTS"][:nb] - base[:, :3]).max() for f in fr)
    still = max(np.abs(f["velocity"][:nb]).max() + np.abs(f["spin"][:nb]).max() for f in fr)
    marked = all((f["fixed"][:nb] == 1).all() and (f["fixed"][nb:] == 0).all() for f in fr)
    check(moved == 0 and still == 0 and marked,
          f"the {nb} base spheres stay where the file put them in all {len(fr)} frames "
          f"(largest move {moved:g} m, speed {still:g}), marked fixed")
    last = fr[-1]
    bottom = (last["POINTS"][nb:, 2] - last["radius"][nb:]).min()
    s = json.load(open(os.path.join(run_dir, "summary.json")))
    e = s["energy_J"]
    floor = sum(abs(m["walls"]) for m in e["work_by_model"])
    check(bottom > 0 and floor == 0,
          f"no free sphere reaches the floor (lowest bottom {bottom * 1e3:.3f} mm; floor's work "
          f"{floor:g} J)")
    g = read_global(os.path.join(run_dir, "global.csv"))
    released = g["potential"][0] - e["potential"]
    check(abs(e["balance_error"]) < 2e-3 * abs(e["work_total"]),
          f"energy closure {abs(e['balance_error']) / abs(e['work_total']):.2e} of the work")
    check(e["kinetic"] < 1e-4 * released,
          f"at rest: kinetic {e['kinetic']:.2e} J against {released:.2e} J released")
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [1, 1.3]})
    energy_panel(a, g)
    # the last frame seen along y, a slab 1.5 mm thick through the middle: base grey, grains
    # shaded by their height
    y, mid = last["POINTS"][:, 1], 3e-3
    sel = np.abs(y - mid) < 0.75e-3
    x, z, r = last["POINTS"][sel, 0] * 1e3, last["POINTS"][sel, 2] * 1e3, last["radius"][sel] * 1e3
    fixed = last["fixed"][sel] == 1
    grains = PatchCollection([Circle((x[k], z[k]), r[k]) for k in np.flatnonzero(~fixed)],
                             cmap="viridis", edgecolor="k", linewidth=0.3)
    grains.set_array(z[~fixed])
    b.add_collection(grains)
    b.add_collection(PatchCollection([Circle((x[k], z[k]), r[k]) for k in np.flatnonzero(fixed)],
                                     facecolor="0.6", edgecolor="k", linewidth=0.3))
    b.axhline(0, color="k", linewidth=1)
    b.set_xlim(0, 6)
    b.set_ylim(-0.2, z.max() + 0.6)
    b.set_aspect("equal")
    b.set_xlabel("x [mm]")
    b.set_ylabel("z [mm]")
    b.set_title(f"t = {last['TIME'][0] * 1e3:.0f} ms, |y - 3 mm| < 0.75 mm: the fixed base (grey) "
                "and the grains on it", fontsize=9)
    fig.suptitle(f"{len(last['radius']) - nb} wet spheres settling onto a rough base of {nb} "
                 "glued spheres")
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, "many_rough_base.png"), dpi=120)


def chute(wet_dir, dry_dir):
    print("wet and dry grains on a rough incline of 30 deg (the chute example)")
    runs = {}
    for name, d in (("wet", wet_dir), ("dry", dry_dir)):
        series = json.load(open(os.path.join(d, "particles.vtk.series")))
        fr = [read_vtk(os.path.join(d, e["name"])) for e in series["files"]]
        free = fr[0]["fixed"] == 0
        t = np.array([f["TIME"][0] for f in fr])
        vx = np.array([f["velocity"][free, 0].mean() for f in fr])
        runs[name] = (t, vx, fr, free, json.load(open(os.path.join(d, "summary.json"))))
    t, vx, fr, free, s = runs["wet"]
    late = t >= 0.1
    check(np.abs(vx[late]).max() < 1e-3,
          f"wet: at rest from 0.1 s on (mean downslope speed at most "
          f"{np.abs(vx[late]).max():.1e} m/s): the bridges hold the layer")
    t, vx, fr, free, s_dry = runs["dry"]
    late = t >= 0.1
    mean = vx[late].mean()
    check(mean > 0.03 and np.abs(vx[late] - mean).max() < 0.25 * mean,
          f"dry: keeps flowing from 0.1 s on (mean downslope speed {mean:.3f} m/s, frames "
          f"within {np.abs(vx[late] - mean).max() / mean:.0%} of it)")
    for name, run in runs.items():
        e = run[4]["energy_J"]
        check(abs(e["balance_error"]) < 2e-3 * abs(e["work_total"]),
              f"{name}: energy closure {abs(e['balance_error']) / abs(e['work_total']):.2e} of "
              "the work (gravity along the periodic x axis: the images' drops counted)")
        sp = run[4]
        check(sp["largest_speed_m_s"] <= sp["speed_bound_m_s"],
              f"{name}: largest speed {sp['largest_speed_m_s']:.3f} m/s within the "
              f"{sp['speed_bound_m_s']:.3f} m/s the step allows (docs/many.md, Speeds beyond "
              "the step's)")
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    for name, (t, vx, fr, free, s) in runs.items():
        a.plot(t * 1e3, vx * 1e2, label=name)
    a.axhline(0, color="k", linewidth=0.5)
    a.set_xlabel("time [ms]")
    a.set_ylabel("mean downslope speed of the grains [cm/s]")
    a.legend()
    # the profiles: downslope speed against height above the floor, the grains of the frames
    # from 0.1 s on in bins of 0.25 mm (bins of at least 20 grain-frames)
    for name, mark in (("dry", "o-"), ("wet", "s-")):
        t, vx, fr, free, s = runs[name]
        z = np.concatenate([f["POINTS"][free, 2] for f, tt in zip(fr, t) if tt >= 0.1]) * 1e3
        v = np.concatenate([f["velocity"][free, 0] for f, tt in zip(fr, t) if tt >= 0.1]) * 1e2
        edges = np.arange(0, z.max() + 0.25, 0.25)
        k = np.digitize(z, edges)
        bins = [j for j in range(1, len(edges)) if (k == j).sum() >= 20]
        b.plot([v[k == j].mean() for j in bins], [0.5 * (edges[j - 1] + edges[j]) for j in bins],
               mark, label=f"{name}, from 0.1 s on")
    b.axvline(0, color="k", linewidth=0.5)
    b.set_xlabel("downslope speed [cm/s]")
    b.set_ylabel("height of the centre above the floor [mm]")
    b.legend()
    fig.suptitle("300 grains on a rough incline of 30 deg: the dry layer flows, the wet one "
                 "is held by its liquid bridges")
    save_and_finish(fig, "many_chute.png")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dir", default=os.path.join(ROOT, "out", "validate", "many"))
    d = ap.parse_args().dir
    os.makedirs(FIGURES, exist_ok=True)
    cradle(os.path.join(d, "cradle"))
    settling(os.path.join(d, "settling"))
    agglomeration(os.path.join(d, "agglomeration"))
    rough_base(os.path.join(d, "rough_base"))
    chute(os.path.join(d, "chute"), os.path.join(d, "chute_dry"))
    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)


if __name__ == "__main__":
    main()
