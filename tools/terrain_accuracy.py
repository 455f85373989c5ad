#!/usr/bin/env python3
"""The terrain scenes against the Monte Carlo reference: `firmament query --scene` with the
tables (`lut`) and with the path tracer (`reference`) over the same views, and the relative
luminance error of each view (docs/accuracy.md, "Terrain").

    python3 tools/terrain_accuracy.py [--firmament target/release/firmament] [--tables earth.lut]
                                      [--samples 20000] [--scene sunset|noon]...
                                      [--set KEY=VALUE]...   # [terrain] keys, e.g. albedo=0
                                      [--clouds] [--reference-cache DIR]

The scenes' clouds are left out (`query --no-clouds`): this measures the terrain, its
shadows and shafts; `--clouds` keeps them (the default scene's cumulus, whose lighting
docs/accuracy.md measures under "Clouds").

`--set` runs a variant of the scenes with those `[terrain]` keys replaced (the decomposition
in docs/accuracy.md: `albedo=0.1`, `albedo=0`, `albedo=0 --set height_scale_m=0 --set
floor_m=0`).

`--reference-cache DIR` keeps each reference query's answer in DIR, named by a hash of its
scene file's text, views, samples and options, and reuses it: a change to the fast path is
measured against the same reference estimates (the reference's own code must not change
meanwhile).

Views within 3 degrees of the sun are left out (its aureole is steeper than a view's
footprint). Standard library only.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import statistics
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# (scene file, sun zenith, sun azimuth, zeniths, azimuths): sky through the shafts, the
# terrain near (looking down) and far (at the horizon).
SCENES = {
    "sunset": ("scenes/valley-sunset.toml", 84.5, 237.0,
               [60, 75, 82, 86, 88.5, 90.2, 92, 95, 100],
               [205, 225, 245, 260, 290, 330]),
    "noon": ("scenes/valley-noon.toml", 28.0, 175.0,
             [40, 70, 84, 88.5, 90.2, 92, 96, 105],
             [0, 20, 60, 120, 200, 280]),
}


def angle(z1, a1, z2, a2):
    d = lambda z, a: (math.sin(math.radians(z)) * math.sin(math.radians(a)),
                      math.sin(math.radians(z)) * math.cos(math.radians(a)),
                      math.cos(math.radians(z)))
    u, v = d(z1, a1), d(z2, a2)
    return math.degrees(math.acos(max(-1.0, min(1.0, sum(p * q for p, q in zip(u, v))))))


def cached_query(cache, binary, scene, views, tables, extra):
    """`query`, its answer kept in the directory `cache` (None: not kept)."""
    if cache is None:
        return query(binary, scene, views, tables, extra)
    key = hashlib.sha256(json.dumps([open(scene, encoding="utf-8").read(), views,
                                     tables or "", extra]).encode()).hexdigest()[:16]
    path = os.path.join(cache, f"terrain-reference-{key}.json")
    if os.path.exists(path):
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    out = query(binary, scene, views, tables, extra)
    os.makedirs(cache, exist_ok=True)
    with open(path + ".tmp", "w", encoding="utf-8") as f:
        json.dump(out, f)
    os.replace(path + ".tmp", path)
    return out


def query(binary, scene, views, tables, extra):
    cmd = [binary, "query", "--scene", scene, "-q"]
    if tables:
        cmd += ["--tables", tables]
    for z, a in views:
        cmd += ["--view", f"{z},{a}"]
    out = subprocess.run(cmd + extra, check=True, capture_output=True, text=True).stdout
    return json.loads(out)["views"]


def variant(scene: str, settings: list[str]) -> str:
    """The scene file with `settings` (KEY=VALUE) in its [terrain] section, in a temporary file."""
    if not settings:
        return os.path.join(ROOT, scene)
    lines = open(os.path.join(ROOT, scene), encoding="utf-8").read().splitlines()
    keys = {kv.split("=", 1)[0].strip() for kv in settings}
    out, in_terrain = [], False
    for line in lines:
        if line.startswith("["):
            in_terrain = line.startswith("[terrain]")
            out.append(line)
            if in_terrain:
                out.extend(settings)
            continue
        if in_terrain and line.split("=", 1)[0].strip() in keys:
            continue
        out.append(line)
    f = tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False, encoding="utf-8")
    f.write("\n".join(out) + "\n")
    f.close()
    return f.name


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("--firmament", default=os.path.join(ROOT, "target", "release", "firmament"))
    p.add_argument("--tables")
    p.add_argument("--samples", type=int, default=20000)
    p.add_argument("--scene", action="append", choices=sorted(SCENES))
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--clouds", action="store_true", help="keep the scenes' clouds")
    p.add_argument("--reference-cache", metavar="DIR",
                   help="keep and reuse the reference's answers in DIR")
    args = p.parse_args()
    for name in args.scene or sorted(SCENES):
        scene, sz, sa, zeniths, azimuths = SCENES[name]
        scene = variant(scene, args.set)
        views = [(z, a) for z in zeniths for a in azimuths if angle(z, a, sz, sa) > 3.0]
        extra = [] if args.clouds else ["--no-clouds"]
        lut = query(args.firmament, scene, views, args.tables, extra)
        ref = cached_query(args.reference_cache, args.firmament, scene, views, args.tables,
                           extra + ["--method", "reference", "--samples", str(args.samples)])
        errors, noise = [], []
        print(f"== {name} ({scene} {' '.join(args.set)}), {len(views)} views, "
              f"{args.samples} paths/wavelength, clouds {'in' if args.clouds else 'out'}")
        print("zenith azimuth      lut_cd_m2      ref_cd_m2   error  ref_noise")
        for (z, a), l, r in zip(views, lut, ref):
            e = l["luminance_cd_m2"] / r["luminance_cd_m2"] - 1.0
            s = r["luminance_cd_m2_stderr"] / r["luminance_cd_m2"]
            errors.append(abs(e))
            noise.append(s)
            kind = "terrain" if z > 90 else "sky/far"
            print(f"{z:6.1f} {a:7.1f} {l['luminance_cd_m2']:14.2f} {r['luminance_cd_m2']:14.2f} "
                  f"{100 * e:+6.1f}% {100 * s:6.2f}%  {kind}")
        errors.sort()
        p95 = errors[min(len(errors) - 1, math.ceil(0.95 * len(errors)) - 1)]
        print(f"{name}: median |error| {100 * statistics.median(errors):.2f}%, "
              f"p95 {100 * p95:.2f}%, max {100 * errors[-1]:.2f}%; "
              f"median reference noise {100 * statistics.median(noise):.2f}%")


if __name__ == "__main__":
    main()
