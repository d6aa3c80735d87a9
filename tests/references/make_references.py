#!/usr/bin/env python3
"""Render small Mitsuba 3 reference images of the shared test scenes.

For every entry of REFERENCES below, the scene's Mitsuba XML (generated from the
authoritative scene.json, see scenes/CONVENTIONS.md) is loaded with only the
film resolution changed (same aspect ratio, same camera, integrator, box filter,
`independent` sampler), and rendered in PASSES independent passes with seeds
SEED0, SEED0+1, ... Each pass uses spp / PASSES samples per pixel. Written per entry:

  NAME.exr      mean of the passes: linear RGB, float32, channels R,G,B (row 0 = top)
  NAME_var.exr  per-pixel variance OF THE MEAN, estimated from the passes:
                sample variance across passes (ddof = 1) / number of passes
  NAME.json     settings, timing and summary statistics

Regenerate (from the repository root):

  pip install mitsuba==3.9.1 numpy
  python3 tests/references/make_references.py

Options: --scenes-dir (default scenes relative to the repository root),
--out (default tests/references/), --only NAME [NAME ...], --spp-scale F (multiply
every spp, e.g. 0.01 for a quick smoke test), --passes N, --seed0 S.
"""

import argparse
import hashlib
import json
import os
import sys
import time
import xml.etree.ElementTree as ET

import numpy as np

MITSUBA_VERSION = "3.9.1"
VARIANT = "scalar_rgb"
PASSES = 8
SEED0 = 0

# name, scene folder, xml file, width, height, total spp (over all passes)
# Resolutions are the scene's own film size halved (aspect ratio kept).
REFERENCES = [
    ("cornell-box",           "cornell-box",  "scene.xml",           128, 128, 4096),
    ("matpreview",            "matpreview",   "scene.xml",           128,  96, 4096),
    ("matpreview-roughmetal", "matpreview",   "scene-roughmetal.xml", 128, 96, 4096),
    ("objects-grid",          "objects-grid", "scene.xml",           128, 128, 4096),
    ("veach-ajar",            "veach-ajar",   "scene.xml",           160,  90, 8192),
]


def repo_root():
    return os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def load_scene(mi, scene_dir, xml_name, width, height, spp_per_pass):
    """Load scene_dir/xml_name with the film resized to width x height.

    Returns (scene, info) where info holds what was found in the XML."""
    path = os.path.join(scene_dir, xml_name)
    with open(path, "rb") as f:
        raw = f.read()
    root = ET.fromstring(raw)
    films = root.findall("./sensor/film")
    if len(films) != 1:
        raise RuntimeError(f"{path}: expected exactly one <sensor><film>, found {len(films)}")
    film = films[0]
    dims = {}
    for el in film.findall("integer"):
        if el.get("name") in ("width", "height"):
            dims[el.get("name")] = el
    if set(dims) != {"width", "height"}:
        raise RuntimeError(f"{path}: film has no integer width/height")
    orig_w, orig_h = int(dims["width"].get("value")), int(dims["height"].get("value"))
    if orig_w * height != orig_h * width:
        raise RuntimeError(f"{path}: {width}x{height} does not keep the aspect ratio of {orig_w}x{orig_h}")
    dims["width"].set("value", str(width))
    dims["height"].set("value", str(height))

    rfilter = film.find("rfilter")
    samplers = root.findall("./sensor/sampler")
    if rfilter is None or rfilter.get("type") != "box":
        raise RuntimeError(f"{path}: expected a box rfilter")
    if len(samplers) != 1 or samplers[0].get("type") != "independent":
        raise RuntimeError(f"{path}: expected an independent sampler")
    integ = root.find("integrator")
    integ_info = {"type": integ.get("type")}
    for el in integ:
        integ_info[el.get("name")] = el.get("value")

    text = ET.tostring(root, encoding="unicode")
    # Relative file names (meshes/..., textures/...) resolve against the scene folder.
    fr = mi.file_resolver()
    saved = mi.FileResolver(fr)
    fr.prepend(os.path.abspath(scene_dir))
    try:
        scene = mi.load_string(text, spp=str(spp_per_pass))
    finally:
        mi.set_file_resolver(saved)
    info = {
        "xml": os.path.relpath(path, os.path.dirname(os.path.abspath(scene_dir))),
        "xml_sha256": hashlib.sha256(raw).hexdigest(),
        "json_sha256": None,
        "original_resolution": [orig_w, orig_h],
        "integrator": integ_info,
    }
    json_path = os.path.splitext(path)[0] + ".json"
    if os.path.exists(json_path):
        with open(json_path, "rb") as f:
            info["json_sha256"] = hashlib.sha256(f.read()).hexdigest()
    return scene, info


def write_exr(mi, path, arr):
    arr = np.ascontiguousarray(arr, dtype=np.float32)
    mi.Bitmap(arr, mi.Bitmap.PixelFormat.RGB).write(path)


def render_reference(mi, scenes_dir, out_dir, name, folder, xml_name, width, height,
                     spp_total, passes, seed0):
    if spp_total % passes != 0:
        raise RuntimeError(f"{name}: spp {spp_total} is not a multiple of {passes} passes")
    spp_pass = spp_total // passes
    scene_dir = os.path.join(scenes_dir, folder)
    t0, c0 = time.perf_counter(), time.process_time()
    scene, info = load_scene(mi, scene_dir, xml_name, width, height, spp_pass)
    imgs = []
    seeds = [seed0 + p for p in range(passes)]
    for p, seed in enumerate(seeds):
        tp = time.perf_counter()
        img = np.array(mi.render(scene, seed=seed, spp=spp_pass), dtype=np.float64)
        if img.shape != (height, width, 3):
            raise RuntimeError(f"{name}: unexpected image shape {img.shape}")
        imgs.append(img)
        print(f"  {name}: pass {p + 1}/{passes} (seed {seed}, {spp_pass} spp) "
              f"{time.perf_counter() - tp:.1f} s", flush=True)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    stack = np.stack(imgs)
    mean = stack.mean(axis=0)
    var_of_mean = stack.var(axis=0, ddof=1) / passes

    if not (np.isfinite(mean).all() and np.isfinite(var_of_mean).all()):
        raise RuntimeError(f"{name}: NaN/Inf in the result")
    if not (mean > 0).any():
        raise RuntimeError(f"{name}: image is all black")

    write_exr(mi, os.path.join(out_dir, name + ".exr"), mean)
    write_exr(mi, os.path.join(out_dir, name + "_var.exr"), var_of_mean)

    mean_rgb = mean.reshape(-1, 3).mean(axis=0)
    mean_var = var_of_mean.reshape(-1, 3).mean(axis=0)
    lum = mean.mean(axis=2)
    lum_var = var_of_mean.mean(axis=2)  # not exact for the channel mean; a noise indicator
    nz = lum > 1e-6
    rel_std_median = float(np.median(np.sqrt(lum_var[nz]) / lum[nz])) if nz.any() else None
    stats = {
        "mean_rgb": [float(x) for x in mean_rgb],
        "mean_var_of_mean_rgb": [float(x) for x in mean_var],
        "relative_noise_rgb": [float(v / (m * m)) if m > 0 else None for v, m in zip(mean_var, mean_rgb)],
        "median_pixel_rel_std_error": rel_std_median,
        "max_pixel": float(mean.max()),
    }
    meta = {
        "name": name,
        "scene": folder,
        **info,
        "resolution": [width, height],
        "spp_total": spp_total,
        "passes": passes,
        "spp_per_pass": spp_pass,
        "seeds": seeds,
        "sampler": "independent",
        "rfilter": "box",
        "mitsuba_version": mi.__version__,
        "variant": mi.variant(),
        "seconds_wall": round(wall, 2),
        "seconds_cpu": round(cpu, 2),
        "threads_cpu_count": os.cpu_count(),
        "files": {"mean": name + ".exr", "var_of_mean": name + "_var.exr"},
        "stats": stats,
    }
    with open(os.path.join(out_dir, name + ".json"), "w") as f:
        json.dump(meta, f, indent=1)
        f.write("\n")
    rn = stats["relative_noise_rgb"]
    print(f"{name}: {width}x{height}, {spp_total} spp ({passes} x {spp_pass}), "
          f"{wall:.1f} s wall, {cpu:.1f} s cpu; mean RGB "
          f"({mean_rgb[0]:.5f}, {mean_rgb[1]:.5f}, {mean_rgb[2]:.5f}); mean var "
          f"({mean_var[0]:.3g}, {mean_var[1]:.3g}, {mean_var[2]:.3g}); rel. noise "
          f"({rn[0]:.3g}, {rn[1]:.3g}, {rn[2]:.3g}); median px rel. std err {rel_std_median:.3g}",
          flush=True)
    return meta


def main():
    root = repo_root()
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes-dir", default=os.path.join(root, "..", "shared", "scenes"))
    ap.add_argument("--out", default=os.path.join(root, "tests", "references"))
    ap.add_argument("--only", nargs="+", metavar="NAME", help="render only these references")
    ap.add_argument("--spp-scale", type=float, default=1.0, help="multiply every spp (rounded to the passes)")
    ap.add_argument("--passes", type=int, default=PASSES)
    ap.add_argument("--seed0", type=int, default=SEED0)
    args = ap.parse_args()

    import mitsuba as mi
    if mi.__version__ != MITSUBA_VERSION:
        print(f"warning: Mitsuba {mi.__version__}, the committed references used {MITSUBA_VERSION}",
              file=sys.stderr)
    mi.set_variant(VARIANT)

    names = [r[0] for r in REFERENCES]
    if args.only:
        unknown = [n for n in args.only if n not in names]
        if unknown:
            ap.error(f"unknown reference(s) {unknown}; known: {names}")
    os.makedirs(args.out, exist_ok=True)
    total = 0.0
    for name, folder, xml_name, w, h, spp in REFERENCES:
        if args.only and name not in args.only:
            continue
        spp = max(args.passes, int(round(spp * args.spp_scale / args.passes)) * args.passes)
        meta = render_reference(mi, args.scenes_dir, args.out, name, folder, xml_name, w, h,
                                spp, args.passes, args.seed0)
        total += meta["seconds_wall"]
    print(f"total {total:.1f} s wall")


if __name__ == "__main__":
    main()
